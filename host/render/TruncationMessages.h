// What a render's truncation report (render/Truncation.h) tells its user:
// where the image may differ from the exact one and by how much it is known,
// each message with advice that, taken, does what it says. Advice is given as
// options in quotes, meant to replace the options of the same names; it always
// names --tolerance with --depth or --min-weight, as either alone asks for a
// fixed tree.
#pragma once

#include <string>
#include <vector>

#include "render/RenderRequest.h"

namespace snell {

// The lines to print on standard error ("snell: warning: ...", "snell: note:
// ..."), in this order: what was estimated rather than bounded, what was
// neither, what the tree budget stopped, what the GPU dropped for want of room.
std::vector<std::string> truncationMessages(const TruncationReport& report, const TraceSettings& settings);

}  // namespace snell
