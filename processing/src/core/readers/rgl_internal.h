// Helpers shared by the RGL reader's translation units (not part of the public API).
#pragma once

#include <string_view>

namespace brdf {

// Strict UTF-8 (RFC 3629): no overlong forms, no surrogates, nothing above U+10FFFF.
bool IsValidUtf8(std::string_view s);

}  // namespace brdf
