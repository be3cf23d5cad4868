#include "render/png_writer.h"

#include <fcntl.h>
#include <png.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>

namespace odemag {
namespace {

struct PngErrorSink {
  char message[256];
};

[[noreturn]] void on_png_error(png_structp png, png_const_charp msg) {
  auto* sink = static_cast<PngErrorSink*>(png_get_error_ptr(png));
  if (sink != nullptr) std::snprintf(sink->message, sizeof(sink->message), "libpng: %s", msg);
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

// Encodes the image into `file`. Only trivially destructible objects live in
// this frame, so libpng's longjmp out of an error is safe. Returns false and
// fills sink->message on failure.
bool encode(std::FILE* file, int width, int height, const std::uint8_t* rgb, int level,
            PngErrorSink* sink) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, on_png_error, on_png_warning);
  if (png == nullptr) {
    std::snprintf(sink->message, sizeof(sink->message), "libpng: cannot create write struct");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(sink->message, sizeof(sink->message), "libpng: cannot create info struct");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_compression_level(png, level);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  const std::size_t stride = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y)
    png_write_row(png, rgb + static_cast<std::size_t>(y) * stride);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

std::string errno_text(int err) { return std::strerror(err); }

void fsync_directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);  // best effort: makes the rename durable
  ::close(fd);
}

bool fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

}  // namespace

bool write_png(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb,
               std::string* error, int compression_level) {
  if (path.empty()) return fail(error, "write_png: empty path");
  if (width <= 0 || height <= 0 || width > 1 << 20 || height > 1 << 20)
    return fail(error, "write_png: bad image size " + std::to_string(width) + "x" + std::to_string(height));
  const std::size_t expected = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3;
  if (rgb.size() != expected)
    return fail(error, "write_png: " + std::to_string(rgb.size()) + " bytes given for a " +
                           std::to_string(width) + "x" + std::to_string(height) + " RGB8 image (" +
                           std::to_string(expected) + " expected)");
  if (compression_level < 0) compression_level = 0;
  if (compression_level > 9) compression_level = 9;

  std::string tmp = path + ".tmp-XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0)
    return fail(error, "write_png: cannot create a temporary file next to " + path + ": " +
                           errno_text(errno));
  ::fchmod(fd, 0644);  // mkstemp creates 0600; frames should be readable like ordinary files
  std::FILE* file = ::fdopen(fd, "wb");
  if (file == nullptr) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    return fail(error, "write_png: fdopen " + tmp + ": " + errno_text(err));
  }

  PngErrorSink sink{};
  bool ok = encode(file, width, height, rgb.data(), compression_level, &sink);
  std::string message = ok ? std::string() : std::string(sink.message) + " (writing " + tmp + ")";
  if (ok && std::fflush(file) != 0) {
    ok = false;
    message = "write_png: writing " + tmp + ": " + errno_text(errno);
  }
  if (ok && ::fsync(::fileno(file)) != 0) {
    ok = false;
    message = "write_png: fsync " + tmp + ": " + errno_text(errno);
  }
  if (std::fclose(file) != 0 && ok) {
    ok = false;
    message = "write_png: closing " + tmp + ": " + errno_text(errno);
  }
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    message = "write_png: rename " + tmp + " -> " + path + ": " + errno_text(errno);
  }
  if (!ok) {
    ::unlink(tmp.c_str());
    return fail(error, message);
  }
  fsync_directory_of(path);
  return true;
}

std::string frame_filename(long index) {
  char name[48];
  std::snprintf(name, sizeof(name), "frame_%05ld.png", index);
  return name;
}

}  // namespace odemag
