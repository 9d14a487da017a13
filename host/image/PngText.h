// The text a PNG file carries beside its pixels (tEXt chunks: the scene, the
// settings, the region of a piece), which the decoder does not return.
#pragma once

#include <string>

#include "image/ImageIO.h"

namespace snell {

// The tEXt chunks of the PNG file `bytes`, in file order; a malformed chunk
// ends the list (the decoder reports what is wrong with the file).
ImageText pngText(const std::string& bytes);

}  // namespace snell
