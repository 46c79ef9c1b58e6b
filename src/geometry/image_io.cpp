// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/image_io.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>

#include "geometry/errors.h"
#include "geometry/output_file.h"

namespace surftex {

namespace {

// Refuse absurd headers before allocating (a corrupt file may claim 10^6 x 10^6).
constexpr long long kMaxPixels = 1LL << 28;  // 268M pixels

Image read_current(OIIO::ImageInput& in, const std::string& path) {
  const OIIO::ImageSpec& spec = in.spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InvalidInputError("image '" + path + "' is empty (" + std::to_string(spec.width) + "x" +
                            std::to_string(spec.height) + ", " + std::to_string(spec.nchannels) +
                            " channels)");
  if (static_cast<long long>(spec.width) * spec.height > kMaxPixels)
    throw InvalidInputError("image '" + path + "' is too large (" + std::to_string(spec.width) +
                            "x" + std::to_string(spec.height) + ")");
  Image img(spec.width, spec.height, spec.nchannels);
  if (!in.read_image(in.current_subimage(), 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT,
                     img.data.data())) {
    // Take every pending message now: OIIO prints the ones left unretrieved
    // when the reader is destroyed, after our own error line.
    std::string why = in.geterror();
    in.close();
    (void)in.geterror();
    (void)OIIO::geterror();
    const auto nl = why.find('\n');
    if (nl != std::string::npos) why.resize(nl);  // the first (root) cause
    throw IOError("cannot decode image '" + path + "' (truncated or corrupt): " + why);
  }
  for (float v : img.data)
    if (!std::isfinite(v)) throw InvalidInputError("image '" + path + "' holds NaN or infinite values");
  return img;
}

std::unique_ptr<OIIO::ImageInput> open_input(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw IOError("image '" + path + "' does not exist");
  if (std::filesystem::is_directory(path, ec)) throw IOError("image '" + path + "' is a folder");
  if (std::filesystem::file_size(path, ec) == 0 && !ec)
    throw IOError("image '" + path + "' is empty (0 bytes)");
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string why = OIIO::geterror();
    throw IOError("cannot read image '" + path + "'" + (why.empty() ? "" : ": " + why));
  }
  return in;
}

OIIO::ImageSpec spec_for(const Image& img, const std::string& path, bool eight_bit) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  bool float_ok = (ext == ".exr" || ext == ".tif" || ext == ".tiff" || ext == ".hdr" || ext == ".pfm");
  OIIO::TypeDesc fmt = (eight_bit || !float_ok) ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
  if (ext == ".exr" && fmt == OIIO::TypeDesc::UINT8) fmt = OIIO::TypeDesc::HALF;
  return OIIO::ImageSpec(img.width, img.height, img.channels, fmt);
}

void check_writable(const Image& img, const std::string& path) {
  if (img.empty()) throw InvalidInputError("cannot write empty image to '" + path + "'");
  if (img.data.size() != static_cast<std::size_t>(img.width) * img.height * img.channels)
    throw InvalidInputError("image buffer size does not match its dimensions for '" + path + "'");
}

}  // namespace

Image read_image(const std::string& path) {
  auto in = open_input(path);
  Image img = read_current(*in, path);
  in->close();
  return img;
}

std::vector<Image> read_image_layers(const std::string& path) {
  auto in = open_input(path);
  std::vector<Image> layers;
  int sub = 0;
  do {
    layers.push_back(read_current(*in, path));
    ++sub;
  } while (in->seek_subimage(sub, 0));
  in->close();
  return layers;
}

void write_image(const std::string& path, const Image& img, const WriteImageOptions& opt) {
  check_writable(img, path);
  AtomicOutputFile out(path, opt.overwrite);
  auto writer = OIIO::ImageOutput::create(path);
  if (!writer) throw IOError("no image writer for '" + path + "': " + OIIO::geterror());
  OIIO::ImageSpec spec = spec_for(img, path, opt.eight_bit);
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
