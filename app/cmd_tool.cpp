#include <cstdio>
#include <string>

#include "commands.h"
#include "errors.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fieldpath/geometry/tool_model.h"

namespace fieldpath::app {

void addToolCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd =
      app.add_subcommand("tool",
                         "Write the mesh of a tool (and holder) in the tool frame: tip at the "
                         "origin, axis +z, mm");
  struct Options {
    std::string shape, holder, out;
    double tol_mm = 0.001;
  };
  auto options = std::make_shared<Options>();
  cmd->add_option("--shape", options->shape,
                  "ball:R[:L] | torus:R:r[:L] | flat:R[:L] (mm; L defaults to 4R)")
      ->required();
  cmd->add_option("--holder", options->holder,
                  "Holder stations z0:r0,z1:r1,... (mm, z from the tip)");
  cmd->add_option("--tol", options->tol_mm, "Chordal tolerance, mm")->capture_default_str();
  cmd->add_option("--out", options->out, "Output mesh (.stl binary, .obj, .ply)")->required();
  cmd->callback([options] {
    common::checkOutputFile(options->out, "--out");
    const geometry::ToolSpec tool = geometry::parseToolSpec(options->shape);
    const geometry::HolderProfile holder = geometry::parseHolderProfile(options->holder);
    if (!(options->tol_mm > 0) || !(options->tol_mm < tool.radius_mm))
      throw InputError("--tol " + std::to_string(options->tol_mm) +
                       ": chordal tolerance must be in (0, R) mm, R = " +
                       std::to_string(tool.radius_mm) + " mm (the tool's radius)");
    const geometry::TriangleMesh mesh = geometry::toolMesh(tool, holder, options->tol_mm);
    geometry::saveMesh(mesh, options->out);
    common::commitOutputs();  // a summary lost from here takes it not away
    const geometry::MeshReport report = geometry::validateMesh(mesh);
    std::printf("%s: %zu triangles, area %.6g mm^2, volume %.6g mm^3, closed %s\n",
                options->out.c_str(), report.triangles, geometry::meshArea(mesh),
                geometry::meshVolume(mesh), report.closed() ? "yes" : "no");
  });
}

}  // namespace fieldpath::app
