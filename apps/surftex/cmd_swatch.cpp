// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex swatch`: writes one of the project's generated mesh swatches
// (shell/swatch_generators.h) for mesh quilting.
#include <cstdio>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/write_mesh.h"
#include "shell/swatch.h"
#include "shell/swatch_generators.h"
#include "surftex/command.h"

namespace surftex::cli {
namespace {
namespace swatch_command {  // named: the unity build joins these files

struct SwatchArgs {
  std::string kind, output;
  int size = 0;
  CommonOptions common;
};

int run_swatch(const SwatchArgs& a) {
  check_output(a.output, {}, a.common.force);
  Mesh m;
  if (a.kind == "chainmail") {
    ChainmailOptions o;
    if (a.size) o.rings_x = o.rings_y = a.size;
    o.seed = a.common.seed;
    make_chainmail_swatch(m, o);
  } else if (a.kind == "weave") {
    WeaveOptions o;
    if (a.size) o.threads_x = o.threads_y = a.size;
    o.seed = a.common.seed;
    make_weave_swatch(m, o);
  } else if (a.kind == "tori") {
    ToriOptions o;
    if (a.size) o.tori_x = o.tori_y = a.size;
    o.seed = a.common.seed;
    make_tori_swatch(m, o);
  } else {
    ScatterOptions o;
    if (a.size) o.size = a.size;
    o.seed = a.common.seed;
    make_scatter_swatch(m, o);
  }
  const Swatch s = make_swatch(m);
  WriteMeshOptions wo;
  wo.overwrite = a.common.force;
  write_mesh(a.output, m, wo);
  nlohmann::json r;
  r["kind"] = a.kind;
  r["output"] = a.output;
  r["faces"] = m.number_of_faces();
  r["vertices"] = m.number_of_vertices();
  r["elements"] = s.elements.size();
  r["extent"] = {s.length(), s.width(), s.height()};
  write_report(a.common, "swatch", r, {{}, {a.output}});
  if (!a.common.quiet)
    std::fprintf(stderr, "%s swatch: %zu elements, %zu faces, %.3g x %.3g x %.3g -> %s\n", a.kind.c_str(),
                 s.elements.size(), static_cast<std::size_t>(m.number_of_faces()), s.length(), s.width(), s.height(),
                 a.output.c_str());
  return 0;
}

SubcommandRegistrar reg{
    {"swatch", "Generate a mesh swatch for quilting: chain mail, weave, scattered blobs or tilted tori",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<SwatchArgs>();
       app.add_option("kind", a->kind, "chainmail | weave | scatter | tori")
           ->required()
           ->check(CLI::IsMember({"chainmail", "weave", "scatter", "tori"}));
       app.add_option("-o,--output", a->output, "Output mesh (.obj, .ply, .off, .glb)")->required();
       app.add_option("--size", a->size,
                      "chainmail: rings per side (1..64, default 4); weave: threads per direction "
                      "(1..64, default 6); scatter: side of the square (5..64, default 10); tori: rings per side (1..64, default 4); 0 = default")
           ->check(CLI::Range(0, 64));
       add_common_options(app, a->common);
       return [a] { return run_swatch(*a); };
     }}};

}  // namespace swatch_command
}  // namespace
}  // namespace surftex::cli
