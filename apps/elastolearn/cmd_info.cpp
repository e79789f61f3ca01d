// elastolearn info FILE: a summary of a tet mesh, surface mesh, trajectory, observation, point
// clouds, scene or learned material.
#include "command.hpp"

#include <elastolearn/core/error.hpp>
#include <elastolearn/io/cloud_file.hpp>
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/io/material_file.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/scene_file.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/learn/stretch_coverage.hpp>
#include <elastolearn/mesh/read_tet_mesh.hpp>
#include <elastolearn/mesh/surface_mesh.hpp>

#include <cstdio>

namespace {

using namespace elastolearn;

void print_box(const Box3& box) {
  std::printf("  bounding box: [%g, %g, %g] .. [%g, %g, %g] (diagonal %g m)\n", box.min().x(),
      box.min().y(), box.min().z(), box.max().x(), box.max().y(), box.max().z(),
      box.diagonal().norm());
}

void print_tet_mesh(const mesh::TetMesh& m) {
  const auto q = m.quality();
  std::printf("  tet mesh: %d vertices, %d tets, %ld surface faces, %zu surface vertices\n",
      m.num_vertices(), m.num_tets(), long(m.surface_faces().rows()), m.surface_vertices().size());
  print_box(m.bounding_box());
  std::printf("  volume %g m^3; tet volumes %g .. %g; dihedral angles %.1f .. %.1f deg; max radius "
              "ratio %.2f\n",
      m.total_volume(), q.min_volume, q.max_volume, q.min_dihedral_deg, q.max_dihedral_deg,
      q.max_radius_ratio);
}

void print_observation(const std::filesystem::path& path) {
  const observe::Observation o = io::read_observation_h5(path);
  const auto [lowest, highest] = std::minmax_element(o.vertex_ids.begin(), o.vertex_ids.end());
  std::printf("  observation: %d frames, t = %g .. %g s (dt = %g s), %d observed vertices\n",
      o.num_frames(), o.start_time, o.start_time + (o.num_frames() - 1) * o.dt, o.dt,
      o.num_observed());
  std::printf("  vertex ids %d .. %d: the rest mesh has at least %d vertices (the file holds no "
              "mesh)\n",
      *lowest, *highest, *highest + 1);
  // Seen entries only: a lost one's position means nothing (it may be NaN). A point's motion
  // is measured from the first frame it was seen in.
  Box3 box;
  double max_motion = 0;
  int never_seen = 0;
  for (int j = 0; j < o.num_observed(); ++j) {
    int first = -1;
    for (int t = 0; t < o.num_frames(); ++t) {
      if (!o.is_valid(t, j))
        continue;
      const Vec3 p = o.positions[static_cast<size_t>(t)].row(j).transpose();
      box.extend(p);
      if (first < 0)
        first = t;
      max_motion = std::max(
          max_motion, (p - o.positions[static_cast<size_t>(first)].row(j).transpose()).norm());
    }
    never_seen += first < 0 ? 1 : 0;
  }
  if (o.valid.size() != 0)
    std::printf("  /observed/valid: %s, %d vertices never seen\n",
        o.has_lost_entries() ? observe::describe_lost_entries(o).c_str() : "nothing lost",
        never_seen);
  std::printf(
      "  observed points over all frames%s:\n", o.valid.size() == 0 ? "" : " (seen entries)");
  print_box(box);
  std::printf("  largest motion of an observed point from %s: %g m\n",
      o.valid.size() == 0 ? "frame 0" : "the first frame it was seen in", max_motion);
  const auto metadata = io::read_observation_metadata(path);
  if (!metadata.contains("noise_sigma"))
    std::printf("  noise: not recorded\n");
  for (const auto& [k, v] : metadata)
    std::printf("  %s: %s\n", k.c_str(), v.c_str());
}

void print_clouds(const std::filesystem::path& path) {
  const capture::PointCloudSequence c = io::read_clouds_h5(path);
  Eigen::Index fewest = c.num_points(), most = 0;
  int empty = 0;
  for (int t = 0; t < c.num_frames(); ++t) {
    fewest = std::min(fewest, c.frame_size(t));
    most = std::max(most, c.frame_size(t));
    empty += c.frame_size(t) == 0;
  }
  std::printf("  point clouds: %d frames, t = %g .. %g s (dt = %g s), %ld points, %ld .. %ld per "
              "frame, %d empty%s%s\n",
      c.num_frames(), c.start_time, c.start_time + (c.num_frames() - 1) * c.dt, c.dt,
      long(c.num_points()), long(fewest), long(most), empty, c.has_normals() ? ", normals" : "",
      c.has_confidence() ? ", confidence" : "");
  if (c.num_points() > 0)
    print_box(
        Box3(c.points.colwise().minCoeff().transpose(), c.points.colwise().maxCoeff().transpose()));
  for (const auto& [k, v] : io::read_clouds_metadata(path))
    if (k != "cameras") // one long JSON line; h5py shows it
      std::printf("  %s: %s\n", k.c_str(), v.c_str());
}

void info(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path.string(), "is a folder, not a file");
  std::printf("%s\n", path.c_str());
  if ((ext == ".h5" || ext == ".hdf5") && io::is_observation_h5(path)) {
    print_observation(path);
  } else if ((ext == ".h5" || ext == ".hdf5") && io::is_clouds_h5(path)) {
    print_clouds(path);
  } else if (ext == ".h5" || ext == ".hdf5") {
    const auto t = io::read_trajectory_h5(path);
    std::printf("  trajectory: %zu frames, t = %g .. %g s, %ld vertices, %ld tets, %ld edges, %ld "
                "faces%s\n",
        t.positions.size(), t.time.empty() ? 0.0 : t.time.front(),
        t.time.empty() ? 0.0 : t.time.back(), long(t.rest_positions.rows()), long(t.tets.rows()),
        long(t.edges.rows()), long(t.faces.rows()),
        t.velocities.empty() ? "" : ", with velocities");
    double max_disp = 0;
    for (const auto& p : t.positions)
      max_disp = std::max(max_disp, (p - t.rest_positions).rowwise().norm().maxCoeff());
    print_box(Box3(t.rest_positions.colwise().minCoeff().transpose(),
        t.rest_positions.colwise().maxCoeff().transpose()));
    std::printf("  largest displacement from rest: %g m\n", max_disp);
    for (const auto& [k, v] : t.metadata)
      std::printf("  %s: %s\n", k.c_str(), v.c_str());
  } else if (const auto json = ext == ".json" ? io::read_json_file(path) : nlohmann::json();
             json.is_object() && json.value("format", "").starts_with("elastolearn-material")) {
    const auto f = io::parse_material_file(json, path.string());
    std::printf("  learned material: %s\n",
        io::describe_material_model(io::material_model(f, path.string())).c_str());
    for (const char* key : { "scene", "observations", "best_iteration", "seconds" })
      if (f.training.contains(key))
        std::printf("  training %s: %s\n", key, f.training.at(key).dump().c_str());
    if (f.training_stretches)
      std::printf("  training stretches: %s\n", learn::describe(*f.training_stretches).c_str());
    else if (f.correction)
      std::printf("  training stretches: not recorded (a file from before they were)\n");
  } else if (ext == ".json") {
    const auto f = io::parse_scene(json, path.string(), path.parent_path()); // already read above
    const auto& s = f.scene;
    std::printf(
        "  scene '%s': %s, density %g, %s mass, %zu fixed and %zu keyframed groups, %zu loads\n",
        s.name.c_str(), s.material.elastic->name().c_str(), s.material.density,
        fem::to_string(s.mass), s.fixed_vertices.size(), s.keyframes.size(), s.loads.size());
    std::printf("  %d frames of dt = %g s (%g s), linear solver %s\n", s.frames, s.dt,
        s.frames * s.dt, sim::to_string(s.linear_solver).c_str());
    print_tet_mesh(s.mesh);
  } else if (ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl") {
    const auto s = mesh::read_surface_mesh(path);
    std::printf("  surface mesh: %ld vertices, %ld triangles, %s, enclosed volume %g\n",
        long(s.vertices.rows()), long(s.faces.rows()), mesh::is_closed(s) ? "closed" : "NOT closed",
        mesh::enclosed_volume(s));
    print_box(Box3(
        s.vertices.colwise().minCoeff().transpose(), s.vertices.colwise().maxCoeff().transpose()));
  } else {
    print_tet_mesh(mesh::read_tet_mesh(path));
  }
}

void add_info_command(CLI::App& root) {
  auto files = std::make_shared<std::vector<std::string>>();
  auto* cmd = root.add_subcommand("info",
      "Summarise a mesh (.node/.ele/.msh/.veg/.obj/.off/.ply/.stl), trajectory, observation or "
      "point clouds (.h5), scene or learned material (.json)");
  cmd->add_option("files", *files, "files to describe")->required();
  cmd->callback([files] {
    for (const auto& f : *files)
      info(f);
  });
}

} // namespace

ELASTOLEARN_COMMAND(90, add_info_command)
