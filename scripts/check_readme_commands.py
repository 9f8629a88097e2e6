#!/usr/bin/env python3
"""Checks the spillway command lines of Markdown files against the binary's own help.

  scripts/check_readme_commands.py BINARY FILE.md|FOLDER [FILE.md|FOLDER ...]

Every command line in a ```sh (or bash, shell, console) code block that runs spillway
(`build/spillway ...`, `spillway ...`, or through a launcher: `mpirun -np 4 build/spillway ...`)
is checked: its subcommand must be one that `BINARY --help` lists, and each option it uses
(`--name` or `-x`) one that the help for that subcommand lists. Placeholders (SCENE, FILE) and
other arguments are not checked. A FOLDER stands for the *.md files in it.

Where each subcommand's options come from: `BINARY SUB --help` when that prints a help of its own
(compare); the main help's option sections when it prints the main help (render); otherwise the
subcommand's synopsis in the main help's usage lines (merge: -o; devices: none).

Prints `file:line: message` for each problem. Exit status: 0 every command line parses, 1 a
problem was found, 2 bad usage or a binary whose help cannot be read.
"""
import os
import re
import shlex
import subprocess
import sys
import tempfile

# A command word after which the real command follows (`mpirun -np 4 build/spillway render`).
LAUNCHERS = {"mpirun", "mpiexec", "srun", "env", "time", "timeout", "nice", "taskset", "sudo",
             "xvfb-run", "valgrind", "perf", "gdb", "strace", "ltrace", "exec", "command"}
SHELL_SEPARATORS = {"|", "||", "&&", ";", "&", "|&"}
FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([\w+-]*)")
SHELL_LANGUAGES = {"sh", "bash", "shell", "console", "zsh"}
# An option as help text writes it: "-o, --output FILE", "--spp N", "[--json]".
OPTION = re.compile(r"(?<![\w-])(--[A-Za-z0-9][A-Za-z0-9-]*|-[A-Za-z])(?![\w-])")
NUMBER = re.compile(r"^-(\d|\.\d)")


def run_help(binary, args):
    """(exit status, stdout + stderr) of BINARY ARGS, run in an empty folder."""
    with tempfile.TemporaryDirectory() as cwd:
        try:
            p = subprocess.run([binary] + args, cwd=cwd, stdin=subprocess.DEVNULL,
                               capture_output=True, text=True, timeout=60)
        except (OSError, subprocess.TimeoutExpired) as e:
            return None, str(e)
    return p.returncode, p.stdout + p.stderr


class Help:
    """What the binary's help says: its subcommands, top-level flags, and each one's options."""

    def __init__(self, binary):
        rc, text = run_help(binary, ["--help"])
        if rc != 0:
            raise RuntimeError("'%s --help' failed (%s): %s" % (binary, rc, text.strip()[:300]))
        self.main = text
        usage, sections = self._split_usage(text)
        self.top_flags = set()
        self.commands = {}  # subcommand -> set of options
        for synopsis in usage:
            words = synopsis.split()
            if "spillway" not in words:
                continue
            rest = words[words.index("spillway") + 1:]
            if not rest:
                continue
            if rest[0].startswith("-"):
                self.top_flags.add(rest[0])
                continue
            opts = self.commands.setdefault(rest[0], set())
            opts.update(OPTION.findall(" ".join(rest[1:])))
        if not self.commands:
            raise RuntimeError("no subcommands found in '%s --help'" % binary)
        for command, opts in self.commands.items():
            rc, sub = run_help(binary, [command, "--help"])
            if rc != 0:
                continue  # no help of its own: its synopsis is all the help lists
            opts.add("--help")
            if sub.strip() == text.strip():
                opts.update(OPTION.findall(sections))  # the main help's option sections
            else:
                opts.update(OPTION.findall(sub))

    @staticmethod
    def _split_usage(text):
        """The usage block's synopses (one per command form, description columns dropped), and the
        rest of the help (its option sections)."""
        lines = text.splitlines()
        synopses, rest, in_usage = [], [], False
        for line in lines:
            if line.strip().lower() == "usage:":
                in_usage = True
                continue
            if in_usage and not line.strip():
                in_usage = False
                continue
            if in_usage:
                body = line.strip()
                if body.startswith("spillway") or body.startswith("mpirun"):
                    # "spillway merge PART... -o IMAGE   add partial ..." -> the part before the
                    # description column.
                    synopses.append(re.split(r"\s{2,}", body)[0])
                continue
            rest.append(line)
        return synopses, "\n".join(rest)


def shell_blocks(path):
    """Yields (line number, text) for every line inside a shell code block of a Markdown file."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    fence = None  # the fence that opened the current block, or None outside blocks
    shell = False
    for number, line in enumerate(lines, 1):
        m = FENCE.match(line)
        if fence is None:
            if m:
                fence = m.group(2)
                shell = m.group(3).lower() in SHELL_LANGUAGES
            continue
        if m and m.group(2).startswith(fence[0]) and len(m.group(2)) >= len(fence) \
                and not m.group(3):
            fence = None
            continue
        if shell:
            yield number, line


def logical_lines(path):
    """Yields (tokens, problem) per command line of the file's shell blocks; each token is
    (line number, text). Lines ending in a backslash continue on the next."""
    pending = []  # tokens of the lines continued so far
    start = None
    for number, line in shell_blocks(path):
        text = line.strip()
        if text.startswith("$ "):
            text = text[2:]
        continued = text.endswith("\\") and not text.endswith("\\\\")
        if continued:
            text = text[:-1]
        try:
            words = shlex.split(text, comments=True)
        except ValueError as e:
            yield [], (number, "cannot split this line as the shell would: %s" % e)
            pending, start = [], None
            continue
        if start is None:
            start = number
        pending += [(number, w) for w in words]
        if not continued:
            yield pending, None
            pending, start = [], None
    if pending:
        yield pending, None


def commands(tokens):
    """Splits a command line's tokens at the shell's separators (|, &&, ;)."""
    segment = []
    for number, word in tokens:
        if word in SHELL_SEPARATORS:
            if segment:
                yield segment
            segment = []
            continue
        ends = word.endswith(";") and len(word) > 1
        segment.append((number, word[:-1] if ends else word))
        if ends:
            yield segment
            segment = []
    if segment:
        yield segment


def spillway_arguments(segment):
    """The tokens after the spillway binary when this command runs it, else None."""
    words = [w for _, w in segment]
    i = 0
    while i < len(words) and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", words[i]):
        i += 1  # VAR=value before the command
    if i == len(words):
        return None
    if os.path.basename(words[i]) == "spillway":
        return segment[i + 1:]
    if os.path.basename(words[i]) not in LAUNCHERS:
        return None
    for j in range(i + 1, len(words)):
        if os.path.basename(words[j]) == "spillway" and not words[j].startswith("-"):
            return segment[j + 1:]
    return None


def check_command(help_, path, start, args):
    problems = []
    if not args:
        return ["%s:%d: spillway without a subcommand (it prints its usage and exits 2)" % (path, start)]
    number, first = args[0]
    first = first.strip("[]")
    if first.startswith("-"):
        if first not in help_.top_flags:
            problems.append("%s:%d: '%s' is not a flag 'spillway --help' lists (it lists: %s)" % (
                path, number, first, ", ".join(sorted(help_.top_flags))))
        return problems
    if first not in help_.commands:
        return ["%s:%d: 'spillway %s': no such subcommand (the help lists: %s)" % (
            path, number, first, ", ".join(sorted(help_.commands)))]
    known = help_.commands[first]
    for number, word in args[1:]:
        for part in word.strip("[]").split("|"):
            part = part.strip("[]")
            if not part.startswith("-") or part in ("-", "--") or NUMBER.match(part):
                continue
            if "=" in part and part.startswith("--"):
                name = part.split("=", 1)[0]
                if name in known:
                    problems.append("%s:%d: '%s': spillway takes an option's value as the next "
                                    "argument ('%s VALUE'), not after '='" % (path, number, part, name))
                    continue
            if part not in known:
                problems.append("%s:%d: 'spillway %s %s': an option its help does not list" % (
                    path, number, first, part))
    return problems


def markdown_files(args):
    files = []
    for a in args:
        if os.path.isdir(a):
            files += sorted(os.path.join(a, f) for f in os.listdir(a) if f.endswith(".md"))
        elif os.path.isfile(a):
            files.append(a)
        else:
            raise FileNotFoundError(a)
    return files


def main(argv):
    if len(argv) < 3 or argv[1] in ("-h", "--help"):
        sys.stderr.write(__doc__)
        return 0 if len(argv) > 1 and argv[1] in ("-h", "--help") else 2
    binary = argv[1]
    if not os.path.isfile(binary) or not os.access(binary, os.X_OK):
        sys.stderr.write("check_readme_commands: '%s' is not an executable file\n" % binary)
        return 2
    try:
        files = markdown_files(argv[2:])
    except FileNotFoundError as e:
        sys.stderr.write("check_readme_commands: no such file or folder: %s\n" % e)
        return 2
    try:
        help_ = Help(os.path.abspath(binary))
    except RuntimeError as e:
        sys.stderr.write("check_readme_commands: %s\n" % e)
        return 2
    problems, checked = [], 0
    for path in files:
        for tokens, problem in logical_lines(path):
            if problem:
                problems.append("%s:%d: %s" % (path, problem[0], problem[1]))
                continue
            for segment in commands(tokens):
                args = spillway_arguments(segment)
                if args is None:
                    continue
                checked += 1
                problems += check_command(help_, path, segment[0][0], args)
    for p in problems:
        print(p)
    print("check_readme_commands: %d spillway command lines in %d files, %d problems" % (
        checked, len(files), len(problems)), file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
