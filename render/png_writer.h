// Atomic RGB8 PNG output with libpng.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace odemag {

// Writes a width x height RGB8 image (tightly packed rows, top row first) as a
// PNG, atomically: the data goes to a fresh "<path>.tmp-XXXXXX" in the same
// directory, is fsync'ed, then rename(2)d over `path` (and the directory is
// fsync'ed), so an interrupted run never leaves a truncated file under the
// final name. Returns false and, if `error` is non-null, sets *error to a
// message on failure; the temporary file is removed then. compression_level
// is zlib's 0..9 (the default 3 favours speed for frame sequences).
bool write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb,
               std::string* error = nullptr, int compression_level = 3);

// "frame_00042.png" for index 42: the name of frame `index` of a sequence.
std::string frame_filename(long index);

}  // namespace odemag
