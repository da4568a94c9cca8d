// How the libraries spell numbers in messages and metadata text: one definition of each
// spelling, shared by every library (brdf::core is below all of them), instead of a private
// copy per file. Messages quote a user's number with NumberText (brdf/core/error.h, "%.9g");
// the spellings here are the others.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace brdf {

// "0x0badf00d": a CRC-32 or another 32-bit word, eight lowercase hexadecimal digits.
std::string Hex32Text(std::uint32_t value);

// "%.17g" ("0.10000000000000001"): a double that reads back bit for bit, for text that is
// parsed again (extrapolation parameters).
std::string ExactNumberText(double value);

// "%g", six significant digits ("20", "0.25", "1e-05"): angles and steps as capture metadata
// records them. A resumed capture compares these texts with the file's, so the spelling is part
// of the .bpc format.
std::string ShortNumberText(double value);

// "0, 20, 40": a list of such numbers (θin slices in messages and remedies), comma separated;
// empty for an empty list.
std::string ShortNumberListText(const std::vector<double>& values);

}  // namespace brdf
