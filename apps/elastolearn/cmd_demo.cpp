// elastolearn demo: simulate the built-in examples (a cantilever released from a bent state, and a
// neo-Hookean sphere with a keyframed top) and write HDF5 + ParaView files.
#include "command.hpp"
#include "demo_scenes.hpp"

#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/scene_output.hpp>

#include <cstdio>
#include <nlohmann/json.hpp>

namespace {

void add_demo_command(CLI::App& root) {
  auto dir = std::make_shared<std::string>("elastolearn-demo");
  auto* cmd = root.add_subcommand("demo", "Run the built-in examples end to end and write HDF5 + ParaView files");
  cmd->add_option("-o,--output-dir", *dir, "where to write the results")->capture_default_str();
  cmd->callback([dir] {
    using namespace elastolearn;
    const std::filesystem::path out(*dir);
    int failures = 0;
    for (const auto& [name, text] : {std::pair{"cantilever", app::kDemoCantilever}, std::pair{"sphere", app::kDemoSphere}}) {
      auto file = io::parse_scene(nlohmann::json::parse(text), std::string("built-in ") + name + ".json", out);
      const auto& s = file.scene;
      std::printf("== %s: %d vertices, %d tets, %s, %d frames of %g s\n", name, s.mesh.num_vertices(), s.mesh.num_tets(),
                  s.material.elastic->name().c_str(), s.frames, s.dt);
      io::SceneOutputOptions options{out / (std::string(name) + ".h5"), out / (std::string(name) + "_vtu"), 1};
      std::filesystem::path pvd;
      const auto report = io::simulate_to_files(s, options, terminal_progress(name), &pvd);
      std::printf("   %s in %.2f s (%.2f Newton iterations/step)\n", report.completed ? "completed" : report.message.c_str(),
                  report.seconds, double(report.newton_iterations) / std::max(1, report.frames_written - 1));
      std::printf("   trajectory: %s\n   paraview:   %s\n", options.trajectory.c_str(), pvd.c_str());
      failures += !report.completed;
    }
    if (failures) throw CLI::RuntimeError(1);
  });
}

} // namespace

ELASTOLEARN_COMMAND(1, add_demo_command)
