// The registry of surface models: one line per model, and the only list of them there is.
// Everything else that names the models is derived from it:
//   * kModel<Name> and kModelCount (shared/types.h), in C++ and GLSL alike;
//   * the BSDF dispatch of shared/bsdf.h, which calls the model's header: <stem>.h defines
//     <fn>BsdfIsDelta, <fn>BsdfConeSpread, <fn>BsdfEval and <fn>BsdfSample (the signatures are
//     bsdf.h's);
//   * the includes of those headers (CMake writes them into generated/surface_model_headers.h);
//   * the shader list of the build: CMake reads the lines below and compiles shaders/<stem>.comp
//     for each (configuring fails if a registered model has no kernel), and the Vulkan pipeline
//     table (one pipeline per model the scene uses);
//   * the scene format: the loader takes `type: <Name>` and reads the keys PARAMS names
//     (host/scene/surface_models.h), each with its one range.
// tests/architecture/surface_models_test.cpp fails for a registered model without its header,
// its kernel or its TEST(<Name>, ...) in tests/bsdf/<stem>_test.cpp. How to add one:
// docs/adding-a-surface-model.md.
//
// X(Name, id, stem, fn, PARAMS) — id counts up from 0 in this order; stem names the model's files
// (snake_case, after the model), fn its functions (the same in camelCase); keep each entry's
// `X(Name, id, stem,` on one line (CMake parses them). PARAMS is read by the C++ loader only.
#ifndef SPILLWAY_SHARED_SURFACE_MODELS_H
#define SPILLWAY_SHARED_SURFACE_MODELS_H

#define SPW_SURFACE_MODELS(X)                                                                      \
    X(Null, 0u, null, null, kNoParams)                                                             \
    X(Lambert, 1u, lambert, lambert, kTakesReflectance | kTakesColour | kTakesTexture)             \
    X(Conductor, 2u, conductor, conductor, kTakesColour | kTakesTexture | kTakesAlpha)             \
    X(Dielectric, 3u, dielectric, dielectric,                                                      \
      kTakesIor | kTakesAlpha | kTakesColour | kTakesTexture | kTakesAbsorption)                   \
    X(MetallicRoughness, 4u, metallic_roughness, metallicRoughness,                                \
      kTakesColour | kTakesTexture | kTakesMetallic | kTakesRoughness | kTakesSpecular)            \
    X(CoatedMetallicRoughness, 5u, coated_metallic_roughness, coatedMetallicRoughness,             \
      kTakesColour | kTakesTexture | kTakesMetallic | kTakesRoughness | kTakesCoat |               \
          kTakesSpecular)                                                                          \
    X(TransmissiveMetallicRoughness, 6u, transmissive_metallic_roughness,                          \
      transmissiveMetallicRoughness,                                                               \
      kTakesColour | kTakesTexture | kTakesMetallic | kTakesRoughness | kTakesIor |                \
          kTakesAbsorption | kTakesTransmission)                                                   \
    X(SheenMetallicRoughness, 7u, sheen_metallic_roughness, sheenMetallicRoughness,                \
      kTakesColour | kTakesTexture | kTakesMetallic | kTakesRoughness | kTakesSpecular |           \
          kTakesSheen)                                                                             \
    X(Principled, 8u, principled, principled,                                                      \
      kTakesColour | kTakesTexture | kTakesMetallic | kTakesRoughness | kTakesCoat |               \
          kTakesPrincipled)

#endif
