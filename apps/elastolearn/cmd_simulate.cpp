// elastolearn simulate scene.json -o traj.h5 [--vtu DIR] [--material learned.json]
#include "command.hpp"

#include <elastolearn/core/command_paths.hpp>
#include <elastolearn/core/error.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/scene_output.hpp>

#include <cstdio>
#include <optional>

namespace {

struct SimulateOptions {
  std::string scene;
  std::string output;
  std::string vtu;
  std::string solver;
  std::string material;
  int frames = 0;
  int every = 0;
  bool quiet = false;
};

void add_simulate_command(CLI::App& root) {
  auto opts = std::make_shared<SimulateOptions>();
  auto* cmd = root.add_subcommand(
      "simulate", "Simulate a scene (JSON) and write its trajectory (HDF5) and ParaView files");
  cmd->add_option("scene", opts->scene, "scene file (elastolearn-scene/1 JSON)")->required();
  cmd->add_option(
      "-o,--output", opts->output, "trajectory HDF5 (default: the scene's output.trajectory)");
  cmd->add_option("--vtu", opts->vtu, "also write a VTU per frame + PVD into this folder");
  cmd->add_option(
      "--solver", opts->solver, "linear solver: cholmod | cg | eigen-ldlt (overrides the scene)");
  cmd->add_option("--material", opts->material,
      "learned material file (elastolearn-material/1 JSON): replaces the scene's material");
  cmd->add_option("--frames", opts->frames, "number of steps (overrides the scene)");
  cmd->add_option("--every", opts->every, "record every k-th frame (overrides the scene)");
  cmd->add_flag("-q,--quiet", opts->quiet, "no progress line");
  cmd->callback([opts] {
    using namespace elastolearn;
    auto file = io::read_scene_file(opts->scene);
    if (!opts->solver.empty())
      file.scene.linear_solver = sim::linear_solver_type_from_string(opts->solver);
    if (opts->frames > 0)
      file.scene.frames = opts->frames;
    io::SceneOutputOptions out;
    if (!opts->output.empty())
      out.trajectory = opts->output;
    else if (file.outputs.trajectory)
      out.trajectory = *file.outputs.trajectory;
    else
      throw InputError(opts->scene, "no output: give -o FILE.h5 or output.trajectory in the scene");
    if (!opts->vtu.empty())
      out.vtu_directory = opts->vtu;
    else
      out.vtu_directory = file.outputs.vtu_directory;
    out.every = opts->every > 0 ? opts->every : file.outputs.every;
    std::vector<CommandInput> inputs = file.inputs;
    if (!opts->material.empty())
      inputs.push_back({ opts->material, "material (--material)" });
    std::vector<CommandOutput> outputs = { { out.trajectory, "trajectory output" } };
    if (out.vtu_directory) {
      outputs.push_back({ *out.vtu_directory, "ParaView folder", OutputKind::folder });
      outputs.push_back({ *out.vtu_directory / (file.scene.name + ".pvd"), "ParaView series" });
    }
    check_command_paths(inputs, outputs);
    std::string material_source = "the scene";
    std::optional<material::StretchRange> trained = file.material_training_stretches;
    if (!opts->material.empty()) {
      const io::MaterialFile material = io::read_material_file(opts->material);
      file.scene.material = io::material_model(material, opts->material);
      trained = material.training_stretches;
      material_source = opts->material;
    }
    const auto& s = file.scene;
    std::printf("scene %s: %d vertices, %d tets, %s, %d frames of dt = %g s, solver %s\n",
        s.name.c_str(), s.mesh.num_vertices(), s.mesh.num_tets(),
        s.material.elastic->name().c_str(), s.frames, s.dt,
        sim::to_string(s.linear_solver).c_str());
    std::printf("material: %s (from %s)\n", io::describe_material_model(s.material).c_str(),
        material_source.c_str());
    std::filesystem::path pvd;
    // A learned correction that recorded its training range: say where this motion leaves it.
    std::optional<learn::StretchCoverage> coverage;
    if (trained && s.material.correction)
      coverage.emplace(s.mesh, trained);
    const auto report = io::simulate_to_files(s, out,
        opts->quiet ? ProgressCallback {} : terminal_progress("simulate"), &pvd,
        coverage ? &*coverage : nullptr);
    std::printf("%s: %d frames in %.2f s (%.1f ms/step, %.2f Newton iterations/step)\n",
        report.completed ? "completed" : "stopped", report.frames_written, report.seconds,
        1e3 * report.seconds / std::max(1, report.frames_written - 1),
        double(report.newton_iterations) / std::max(1, report.frames_written - 1));
    if (report.frames_written > 0)
      std::printf("trajectory: %s\n", out.trajectory.c_str());
    if (!pvd.empty())
      std::printf("paraview:   %s\n", pvd.c_str());
    if (coverage)
      std::fputs(learn::coverage_report(*coverage).c_str(), stdout);
    if (!report.completed) {
      std::fprintf(stderr, "elastolearn: error: %s\n", report.message.c_str());
      throw CLI::RuntimeError(1);
    }
  });
}

} // namespace

ELASTOLEARN_COMMAND(10, add_simulate_command)
