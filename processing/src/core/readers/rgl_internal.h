// Helpers shared by the RGL reader's translation units (not part of the public API).
#pragma once

namespace brdf {

// The 12 bytes an RGL tensor file (.bsdf) starts with: "tensor_file" and a NUL.
inline constexpr char kTensorFileMagic[12] = {'t', 'e', 'n', 's', 'o', 'r',
                                              '_', 'f', 'i', 'l', 'e', '\0'};

}  // namespace brdf
