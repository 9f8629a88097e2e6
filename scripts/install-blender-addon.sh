#!/usr/bin/env bash
# Installs the Spillway render engine add-on (blender/spillway_render) into Blender's user
# add-ons, enables it and names the spillway binary in its preferences:
#   scripts/install-blender-addon.sh [SPILLWAY_BINARY]   (default: this tree's build/spillway)
# Then Spillway is a render engine in Blender's Render properties, and
#   blender -b FILE.blend -E SPILLWAY -f 1
# renders with it headless. BLENDER (default: blender) names the Blender to install into.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [[ "${1:-}" == -h || "${1:-}" == --help ]]; then
    sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
    exit 0
fi
blender="${BLENDER:-blender}"
# Blender's Python finds its standard library from the first python3 on PATH: not a pyenv one.
PATH="$(printf '%s' "$PATH" | tr ':' '\n' | grep -v '\.pyenv' | paste -sd:)"
binary="$(realpath -m "${1:-$root/build/spillway}")"
[ -x "$binary" ] || { echo "install-blender-addon: no spillway binary at $binary (build it, or name it)" >&2; exit 2; }
command -v "$blender" >/dev/null || { echo "install-blender-addon: no Blender ($blender)" >&2; exit 2; }
"$blender" -b --factory-startup --python-expr "
import bpy, os, shutil, sys, addon_utils
addons = bpy.utils.user_resource('SCRIPTS', path='addons', create=True)
target = os.path.join(addons, 'spillway_render')
shutil.rmtree(target, ignore_errors=True)
shutil.copytree('$root/blender/spillway_render', target)
addon_utils.enable('spillway_render', default_set=True, persistent=True)
bpy.context.preferences.addons['spillway_render'].preferences.binary = '$binary'
bpy.ops.wm.save_userpref()
print('install-blender-addon: installed in', target, 'with', '$binary')
" 2>&1 | grep "install-blender-addon" || { echo "install-blender-addon: Blender failed" >&2; exit 1; }
