// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex convert IN -o OUT`: read any supported mesh, repair it, write it.
#include <cstdio>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"

namespace surftex::cli {
namespace {

SubcommandRegistrar reg{
    {"convert", "Convert a mesh between formats (in: OFF, OBJ, PLY, STL; out: OBJ, PLY, OFF, GLB)",
     [](CLI::App& app) -> std::function<int()> {
       auto input = std::make_shared<std::string>();
       auto output = std::make_shared<std::string>();
       auto texture = std::make_shared<std::string>();
       auto common = std::make_shared<CommonOptions>();
       auto no_tri = std::make_shared<bool>(false);
       app.add_option("input", *input, "Input mesh (.off, .obj, .ply, .stl; other names by content)")->required();
       app.add_option("-o,--output", *output,
                      "Output mesh; the format follows the extension: .obj, .ply (binary), .off, .glb")
           ->required();
       app.add_option("--texture", *texture,
                      "Image to attach as texture (OBJ: written as <stem>.png with an .mtl; GLB: embedded). "
                      "Default: none");
       app.add_flag("--no-triangulate", *no_tri,
                    "Keep polygons instead of triangulating them (default: triangulate; GLB always "
                    "stores triangles)");
       add_common_options(app, *common);
       return [=] {
         auto limit = apply_thread_limit(common->threads);
         require_input_file(*input, "input mesh");
         std::vector<std::string> inputs{*input};
         if (!texture->empty()) {
           require_input_file(*texture, "texture");
           inputs.push_back(*texture);
         }
         check_output(*output, inputs, common->force);
         Timer timer;
         Mesh mesh;
         SoupRepairCounts c;
         SoupToMeshOptions ropt;
         ropt.triangulate = !*no_tri;
         read_mesh(*input, mesh, ropt, &c);
         const double read_s = timer.seconds();
         Image tex;
         WriteMeshOptions wopt;
         wopt.overwrite = common->force;
         if (!texture->empty()) {
           tex = read_image(*texture);
           wopt.texture = &tex;
         }
         timer.reset();
         write_mesh(*output, mesh, wopt);
         const double write_s = timer.seconds();
         if (!common->quiet)
           std::printf("%s: %zu vertices, %zu faces -> %s\n", input->c_str(), c.output_vertices, c.output_faces,
                       output->c_str());
         nlohmann::json r;
         r["input"] = *input;
         r["output"] = *output;
         r["vertices"] = c.output_vertices;
         r["faces"] = c.output_faces;
         r["points_in_file"] = c.input_points;
         r["polygons_in_file"] = c.input_polygons;
         r["timings"] = {{"read_seconds", read_s}, {"write_seconds", write_s}};
         write_report(*common, "convert", r);
         return 0;
       };
     }}};

}  // namespace
}  // namespace surftex::cli
