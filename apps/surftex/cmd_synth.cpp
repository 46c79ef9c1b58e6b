// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex synth`: grow a 2D texture from an exemplar image (two-pass
// Efros-Leung after Gorla et al. 2003, 3.3, optionally oriented by an angle
// field, 3.3.2), and report time and quality figures.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <string>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "surftex/command.h"
#include "texture/bidirectional_similarity.h"
#include "texture/efros_leung.h"
#include "texture/graphcut_synthesis.h"
#include "texture/histogram_distance.h"
#include "texture/image_ops.h"
#include "texture/synthesis_json.h"

namespace surftex::cli {
namespace {
namespace synth_command {  // named: the unity build joins these files

struct SynthArgs {
  std::string exemplar, output, size = "256x256", method = "el2pass", angle_field;
  int window = 11, first_window = 0, preselect = 0, rotations = 64;
  double angle_deg = 0.0, coherence = ElOptions{}.coherence;
  std::string search = "approximate";
  bool has_angle = false, periodic = false;
  CommonOptions common;
};

void parse_size(const std::string& s, int& w, int& h) {
  const auto x = s.find_first_of("xX");
  try {
    if (x == std::string::npos) throw std::invalid_argument(s);
    std::size_t a = 0, b = 0;
    w = std::stoi(s.substr(0, x), &a);
    h = std::stoi(s.substr(x + 1), &b);
    if (a != x || b != s.size() - x - 1) throw std::invalid_argument(s);
  } catch (const std::exception&) {
    throw InvalidInputError("--size '" + s + "' is not WIDTHxHEIGHT");
  }
  if (w < 1 || h < 1 || w > 16384 || h > 16384)
    throw InvalidInputError("--size " + s + ": each side must be in 1..16384");
}

// Angle field file: an EXR holds radians as they are; any other format is
// read as grey values 0..1 mapped linearly to 0..pi (directions without sign,
// which is what a grey image can encode). The first channel is used and the
// field is resized (bilinear) to the output size if needed.
Image load_angle_field(const std::string& path, int w, int h) {
  Image img = read_image(path);
  Image field = img.channels == 1 ? img : luminance(img);
  if (img.channels == 2) field = luminance(img);  // first channel
  std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext != ".exr")
    for (float& v : field.data) v = static_cast<float>(v * M_PI);
  if (field.width != w || field.height != h) field = resize_bilinear(field, w, h);
  return field;
}

// Two-pass Efros-Leung (Gorla 3.3), optionally oriented (3.3.2).
ElResult run_el2pass(const SynthArgs& a, const Image& exemplar, int w, int h) {
  ElInput in;
  in.exemplars = {exemplar};
  in.target = Image(w, h, exemplar.channels);
  if (!a.angle_field.empty())
    in.angle = load_angle_field(a.angle_field, w, h);
  else if (a.has_angle)
    in.angle = Image(w, h, 1, static_cast<float>(a.angle_deg * M_PI / 180.0));
  ElOptions opt;
  opt.window = a.window;
  opt.first_pass_window = a.first_window;
  opt.preselect = a.preselect;
  opt.rotations = a.rotations;
  opt.search = a.search == "exhaustive" ? ElSearch::Exhaustive : ElSearch::Approximate;
  opt.periodic_exemplar = a.periodic;
  opt.coherence = a.coherence;
  opt.seed = a.common.seed;
  opt.progress = terminal_progress(a.common.quiet);
  return efros_leung_synthesize(in, opt);
}

int run(const SynthArgs& a) {
  require_input_file(a.exemplar, "exemplar");
  std::vector<std::string> inputs{a.exemplar};
  if (!a.angle_field.empty()) {
    require_input_file(a.angle_field, "angle field");
    inputs.push_back(a.angle_field);
  }
  check_output(a.output, inputs, a.common.force);
  int w = 0, h = 0;
  parse_size(a.size, w, h);
  if (a.method == "graphcut" && (!a.angle_field.empty() || a.has_angle))
    throw InvalidInputError("--angle / --angle-field need --method el2pass (graph-cut synthesis is not oriented)");
  auto limit = apply_thread_limit(a.common.threads);
  const Image exemplar = read_image(a.exemplar);
  check_budget(estimate_synth(w, h, exemplar.width, exemplar.height, a.window, a.rotations, a.method == "graphcut"),
               a.common);
  Timer timer;
  ElResult r;
  if (a.method == "graphcut") {
    // Kwatra et al. 2003 (texture/graphcut_synthesis.h), sub-patch matching by default.
    GraphcutOptions gopt;
    gopt.seed = a.common.seed;
    gopt.progress = terminal_progress(a.common.quiet);
    r.image = graphcut_synthesize(exemplar, w, h, gopt);
  } else {
    r = run_el2pass(a, exemplar, w, h);
  }
  const double seconds = timer.seconds();
  write_image(a.output, r.image, {.eight_bit = true, .overwrite = true});
  Timer mt;
  BidirectionalOptions bo;
  bo.periodic_exemplar = a.periodic;
  bo.stride = std::max(1, std::min(w, h) / 128);  // subsample big outputs
  bo.max_candidates = kReportMaxCandidates;  // approximate (an upper bound), as the surface fidelity
  bo.search_eps = kReportSearchEps;
  // Completeness from at most ~16K exemplar positions (a regular subsample).
  const double ex_patches = double(exemplar.width) * exemplar.height;
  bo.exemplar_stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(ex_patches / 16384.0))));
  const BidirectionalResult bs = bidirectional_similarity(r.image, exemplar, bo);
  const double chi = histogram_chi_square(r.image, exemplar);
  nlohmann::json rep = a.method == "el2pass" ? to_json(r) : nlohmann::json::object();
  rep["method"] = a.method;
  rep["exemplar"] = a.exemplar;
  rep["output"] = a.output;
  rep["width"] = w;
  rep["height"] = h;
  if (a.method == "el2pass") {
    rep["preselect"] = a.preselect > 0 ? a.preselect : exemplar.width;
    rep["search"] = a.search;
  }
  rep["seconds"] = {{"synthesis", seconds}};
  rep["texels_per_second"] = (w * static_cast<double>(h)) / std::max(seconds, 1e-9);
  rep["bidirectional_similarity"] = to_json(bs, bo);
  rep["histogram_chi_square"] = chi;
  rep["seconds"]["metrics"] = mt.seconds();
  write_report(a.common, "synth", rep, {inputs, {a.output}});
  if (!a.common.quiet)
    std::printf("%s: %dx%d in %.2f s (%.0f texels/s), coherence %.5f, completeness %.5f, "
                "histogram chi2 %.4f\n",
                a.output.c_str(), w, h, seconds, w * static_cast<double>(h) / seconds,
                bs.coherence, bs.completeness, chi);
  return 0;
}

SubcommandRegistrar reg{
    {"synth", "Grow a 2D texture image from an exemplar (two-pass Efros-Leung, Gorla 2003)",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<SynthArgs>();
       app.add_option("EXEMPLAR", a->exemplar, "Exemplar image (any format OpenImageIO reads)")
           ->required();
       app.add_option("-o,--output", a->output, "Output image (PNG, EXR, ...)")->required();
       app.add_option("--size", a->size, "Output size WIDTHxHEIGHT, each 1..16384 (default 256x256)");
       app.add_option("--method", a->method,
                      "el2pass: two-pass Efros-Leung (Gorla 2003); graphcut: graph-cut textures "
                      "(default el2pass)")
           ->check(CLI::IsMember({"el2pass", "graphcut"}));
       app.add_option("--window", a->window,
                      "Full (second-pass, Gaussian-weighted) neighbourhood diameter, 3..51; even "
                      "sizes allowed (default 11)")
           ->check(CLI::Range(3, 51));
       app.add_option("--first-window", a->first_window,
                      "First-pass (unweighted) neighbourhood diameter, 3..window; 0 = "
                      "round(window*5/12), at least 3 (default 0)")
           ->check(CLI::Range(0, 51));
       app.add_option("--preselect", a->preselect,
                      "Candidates kept by the first pass for the second, >= 0; 0 = exemplar "
                      "width, one scanline (default 0)")
           ->check(CLI::NonNegativeNumber);
       auto* af = app.add_option("--angle-field", a->angle_field,
                                 "Per-pixel texture orientation: an EXR in radians, or a grey "
                                 "image whose 0..1 maps to 0..pi; resized to --size if needed. "
                                 "Angles turn the texture counter-clockwise as displayed");
       app.add_option("--angle", a->angle_deg,
                      "Constant texture orientation in degrees (counter-clockwise), any real; "
                      "default: none (no rotation)")
           ->excludes(af)
           ->each([a](const std::string&) { a->has_angle = true; });
       app.add_option("--rotations", a->rotations,
                      "Number of pre-rotated exemplars for oriented synthesis, 1..128 (default 64)")
           ->check(CLI::Range(1, 128));
       app.add_option("--search", a->search,
                      "First-pass search: approximate (coherent and kd-tree candidates, cost independent "
                      "of the exemplar size) or exhaustive (every exemplar position, Gorla 2003 as "
                      "published; slow on large exemplars) (default approximate)")
           ->check(CLI::IsMember({"approximate", "exhaustive"}));
       app.add_option("--coherence", a->coherence,
                      "el2pass: continue a neighbour's source region when its error is within (1 + this) "
                      "of the best match, so that bricks and tiles come out whole; 0 = Gorla's random "
                      "pick among the best (default 5)")
           ->check(CLI::Range(0.0, 100.0));
       app.add_flag("--periodic", a->periodic,
                    "The exemplar tiles seamlessly: neighbourhoods wrap around its edges "
                    "(default off)");
       add_common_options(app, a->common);
       return [a] { return run(*a); };
     }}};

}  // namespace synth_command
}  // namespace
}  // namespace surftex::cli
