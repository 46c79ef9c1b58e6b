// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>

#include <unistd.h>

#include "geometry/errors.h"
#include "geometry/file_extension.h"
#include "geometry/image_container.h"
#include "geometry/output_file.h"

namespace surftex {

namespace {

// What a decoder prints on stderr itself while pixels are decoded (libpng
// writes "libpng error: ..." before OpenImageIO reports the failure): held in
// a temporary file, then folded into our error (a refusal stays one `error:`
// line) or, after a successful decode, passed on to stderr unchanged.
class StderrCapture {
 public:
  StderrCapture() {
    std::fflush(stderr);
    file_ = std::tmpfile();
    if (file_) saved_ = dup(2);
    if (saved_ >= 0 && dup2(fileno(file_), 2) < 0) {
      close(saved_);
      saved_ = -1;
    }
  }
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;
  ~StderrCapture() {
    restore();
    if (file_) std::fclose(file_);
  }
  /// Restores stderr and returns what was written meanwhile (at most 4 kB).
  std::string release() {
    restore();
    std::string text;
    if (!file_) return text;
    std::rewind(file_);
    char buf[4096];
    text.assign(buf, std::fread(buf, 1, sizeof buf, file_));
    return text;
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    dup2(saved_, 2);
    close(saved_);
    saved_ = -1;
  }
  std::FILE* file_ = nullptr;
  int saved_ = -1;
};

// Runs a decoder step with stderr captured: after a success what it printed
// is passed on unchanged; after a failure it is left in `printed` for the
// refusal (with_printed).
template <class Step>
bool quietly(std::string& printed, Step step) {
  StderrCapture capture;
  const bool ok = step();
  printed = capture.release();
  if (ok && !printed.empty()) std::fputs(printed.c_str(), stderr);
  return ok;
}

// OpenImageIO's reason `why` with the first line a decoder printed itself
// added (when it says something new), for a one-line refusal.
std::string with_printed(std::string why, std::string printed) {
  printed.resize(std::min(printed.find('\n'), printed.size()));
  const auto colon = printed.rfind(": ");  // "libpng error: X" says X, which OpenImageIO may say too
  const std::string said = colon == std::string::npos ? printed : printed.substr(colon + 2);
  if (!said.empty() && why.find(said) == std::string::npos) why += (why.empty() ? "" : "; ") + printed;
  return why;
}

// Takes every pending OpenImageIO message (the reader's and the global
// ones): OIIO prints those left unretrieved when the reader is destroyed, and
// aborts once more than 16 MB accumulate (a TIFF claiming 2^31-1 rows that
// fail one by one did). Returns the first line (the root cause).
std::string take_errors(OIIO::ImageInput* in) {
  std::string why = in ? in->geterror() : std::string();
  const std::string global = OIIO::geterror();
  if (why.empty()) why = global;
  const auto nl = why.find('\n');
  if (nl != std::string::npos) why.resize(nl);
  if (why.size() > 200) why.resize(200);
  return why;
}

void check_spec(const OIIO::ImageSpec& spec, const std::string& path, const ImageLimits& lim) {
  const std::string dims = std::to_string(spec.width) + "x" + std::to_string(spec.height) + ", " +
                           std::to_string(spec.nchannels) + " channels";
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InvalidInputError("image '" + path + "' is empty (" + dims + ")");
  if (spec.depth > 1)
    throw InvalidInputError("image '" + path + "' is a volume (" + std::to_string(spec.depth) + " slices); only 2D images are read");
  if (spec.deep) throw InvalidInputError("image '" + path + "' is a deep image; only flat images are read");
  if (spec.nchannels > ImageLimits::kMaxChannels)
    throw InvalidInputError("image '" + path + "' has " + std::to_string(spec.nchannels) + " channels (at most " +
                            std::to_string(ImageLimits::kMaxChannels) + " are read)");
  const long long w = spec.width, h = spec.height;
  lim.check(w, h, lim.max_side(), path,
            std::to_string(spec.nchannels) + " channels, " + std::to_string(w * h * spec.nchannels * 4 / (1 << 20)) +
                " MiB decoded");
}

Image read_current(OIIO::ImageInput& in, const std::string& path) {
  const OIIO::ImageSpec& spec = in.spec();
  check_spec(spec, path, image_limits());
  Image img(spec.width, spec.height, spec.nchannels);
  std::string printed;
  const bool decoded = quietly(printed, [&] {
    return in.read_image(in.current_subimage(), 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, img.data.data());
  });
  if (!decoded) {
    const std::string why = with_printed(take_errors(&in), printed);
    in.close();
    (void)take_errors(&in);
    throw IOError("cannot decode image '" + path + "' (truncated or corrupt): " + why);
  }
  for (float v : img.data)
    if (!std::isfinite(v)) throw InvalidInputError("image '" + path + "' holds NaN or infinite values");
  return img;
}

std::unique_ptr<OIIO::ImageInput> open_input(const std::string& path, const ImageLimits& lim) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw IOError("image '" + path + "' does not exist");
  if (std::filesystem::is_directory(path, ec)) throw IOError("image '" + path + "' is a folder");
  if (std::filesystem::file_size(path, ec) == 0 && !ec)
    throw IOError("image '" + path + "' is empty (0 bytes)");
  // The format from the file's first bytes, one decoder only: OpenImageIO
  // alone would try every plugin it has (DICOM, RAW, video, ...) on a file
  // its extension does not name.
  const std::string format = sniff_image_format(path);
  check_image_container(path, format, lim);
  auto in = OIIO::ImageInput::create(format);
  OIIO::ImageSpec spec;
  std::string printed;
  const bool opened = in && quietly(printed, [&] { return in->open(path, spec); });
  if (!opened) {
    const std::string why = with_printed(take_errors(in.get()), printed);
    throw IOError("cannot read image '" + path + "' as " + format + (why.empty() ? "" : ": " + why));
  }
  (void)take_errors(in.get());  // warnings of a header that opened
  return in;
}

OIIO::ImageSpec spec_for(const Image& img, const std::string& path, bool eight_bit, bool sixteen_bit = false) {
  const std::string ext = lower_extension(path);
  bool float_ok = (ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".hdr" || ext == ".pfm");
  OIIO::TypeDesc fmt = (eight_bit || !float_ok) ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
  if (ext == ".exr" && fmt == OIIO::TypeDesc::UINT8) fmt = OIIO::TypeDesc::HALF;
  if (sixteen_bit && ext != ".exr") fmt = OIIO::TypeDesc::UINT16;
  OIIO::ImageSpec spec(img.width, img.height, img.channels, fmt);
  // The TIFF writer stamps the current time into its DateTime tag unless one
  // is given: a fixed one keeps the same input and seed giving the same bytes.
  if (ext == ".tif" || ext == ".tiff") spec.attribute("DateTime", "2000:01:01 00:00:00");
  return spec;
}

void check_writable(const Image& img, const std::string& path) {
  if (img.empty()) throw InvalidInputError("cannot write empty image to '" + path + "'");
  if (img.data.size() != static_cast<std::size_t>(img.width) * img.height * img.channels)
    throw InvalidInputError("image buffer size does not match its dimensions for '" + path + "'");
}

}  // namespace

ImageHeader read_image_header(const std::string& path, const ImageLimits& limits) {
  auto in = open_input(path, limits);
  const OIIO::ImageSpec spec = in->spec();
  ImageHeader h;
  h.width = spec.width;
  h.height = spec.height;
  h.channels = spec.nchannels;
  h.format = in->format_name();
  in->close();
  (void)take_errors(in.get());
  check_spec(spec, path, limits);
  return h;
}

Image read_image(const std::string& path) {
  auto in = open_input(path, image_limits());
  Image img = read_current(*in, path);
  in->close();
  return img;
}

std::vector<Image> read_image_layers(const std::string& path) {
  auto in = open_input(path, image_limits());
  std::vector<Image> layers;
  int sub = 0;
  long long bytes = 0;
  do {
    const OIIO::ImageSpec& spec = in->spec();
    check_spec(spec, path, image_limits());  // before the product below (no overflow)
    bytes += static_cast<long long>(spec.width) * spec.height * spec.nchannels * 4;
    if (bytes > 4 * image_limits().max_bytes())
      throw InvalidInputError("image '" + path + "': its " + std::to_string(sub + 1) + " layers hold more than " +
                              std::to_string(4 * image_limits().max_bytes() >> 20) +
                              " MiB decoded (4 times the per-image limit; pass --max-image-pixels to raise it)");
    layers.push_back(read_current(*in, path));
    ++sub;
  } while (in->seek_subimage(sub, 0));
  (void)take_errors(in.get());
  in->close();
  return layers;
}

void write_image(const std::string& path, const Image& img, const WriteImageOptions& opt) {
  check_writable(img, path);
  AtomicOutputFile out(path, opt.overwrite);
  auto writer = OIIO::ImageOutput::create(path);
  if (!writer) throw IOError("no image writer for '" + path + "': " + OIIO::geterror());
  OIIO::ImageSpec spec = spec_for(img, path, opt.eight_bit, opt.sixteen_bit);
  if (!writer->open(out.temp_path(), spec))
    throw IOError("cannot open '" + path + "' for writing: " + writer->geterror());
  if (!writer->write_image(OIIO::TypeDesc::FLOAT, img.data.data()))
    throw IOError("cannot write '" + path + "': " + writer->geterror());
  if (!writer->close()) throw IOError("cannot finish '" + path + "': " + writer->geterror());
  out.commit();
}

void write_image_layers(const std::string& path, const std::vector<Image>& layers,
                        const WriteImageOptions& opt) {
  if (layers.empty()) throw InvalidInputError("no layers to write to '" + path + "'");
  for (const Image& l : layers) {
    check_writable(l, path);
    if (l.channels != layers[0].channels)
      throw InvalidInputError("layers written to '" + path + "' differ in channel count");
  }
  AtomicOutputFile out(path, opt.overwrite);
  auto writer = OIIO::ImageOutput::create(path);
  if (!writer) throw IOError("no image writer for '" + path + "': " + OIIO::geterror());
  if (!writer->supports("multiimage"))
    throw IOError("format of '" + path + "' cannot hold several layers (use .tif or .exr)");
  std::vector<OIIO::ImageSpec> specs;
  for (const Image& l : layers) specs.push_back(spec_for(l, path, opt.eight_bit));
  if (!writer->open(out.temp_path(), static_cast<int>(specs.size()), specs.data()))
    throw IOError("cannot open '" + path + "' for writing: " + writer->geterror());
  for (std::size_t i = 0; i < layers.size(); ++i) {
    if (i > 0 && !writer->open(out.temp_path(), specs[i], OIIO::ImageOutput::AppendSubimage))
      throw IOError("cannot append layer " + std::to_string(i) + " to '" + path + "': " + writer->geterror());
    if (!writer->write_image(OIIO::TypeDesc::FLOAT, layers[i].data.data()))
      throw IOError("cannot write layer " + std::to_string(i) + " of '" + path + "': " + writer->geterror());
  }
  if (!writer->close()) throw IOError("cannot finish '" + path + "': " + writer->geterror());
  out.commit();
}

}  // namespace surftex
