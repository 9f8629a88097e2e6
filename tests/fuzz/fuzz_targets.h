// The fuzzing targets (scripts/fuzz.sh), shared by the libFuzzer harnesses and by the test that
// replays every input kept in tests/fuzz/ (seeds and the crashers fuzzing found) in the normal
// suite. A target returns how the input ended; anything but Accepted or Rejected is a bug.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace spw::fuzz {

enum class Outcome {
    Accepted,   // loaded (and, for a scene, rendered at 4 x 4 pixels)
    Rejected,   // a SceneError: the input is bad and was reported so
    Unexpected, // any other exception: a bug (what() in `detail`)
};

// A scene file: the bytes up to a line "#@obj" are scene.yaml, the rest mesh.obj, written into
// a private folder that also holds tex.png (a valid 4 x 4 image) for Standard textures. A scene
// that loads is rendered by the reference backend at 4 x 4 pixels, 1 sample, depth <= 3: every
// ray Embree sees must be valid.
Outcome scene(const std::uint8_t* data, std::size_t size, std::string* detail = nullptr);
// A glTF file: bytes that begin with the binary container's magic ("glTF") written as model.glb,
// the rest as model.gltf, into the same private folder (tex.png beside it); one that loads is
// rendered as a scene is.
Outcome gltf(const std::uint8_t* data, std::size_t size, std::string* detail = nullptr);
// An OBJ file alone, through the loader's OBJ reader with an identity transform.
Outcome obj(const std::uint8_t* data, std::size_t size, std::string* detail = nullptr);
// A checkpoint or partial render (an EXR with Spillway's state channels), through the reader
// --resume and merge use; one that reads is merged with itself, as `merge A A` would. A file
// that is not a valid checkpoint must be refused with a message (std::runtime_error or
// std::invalid_argument: Rejected); anything else, an allocation failure included, is a bug.
Outcome checkpoint(const std::uint8_t* data, std::size_t size, std::string* detail = nullptr);

} // namespace spw::fuzz
