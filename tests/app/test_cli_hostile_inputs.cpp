// The hostile-input corpus: every reader and every command of `elastolearn` is fed empty,
// truncated, garbled and malicious files (NaN, huge counts, negative indices, inverted tets,
// unknown keys), an output that is one of its inputs, and an output that cannot be written.
// Each case must end with exactly one error line on stderr naming the file, field or line, exit
// code 1 or 2 (not a crash: no signal, no internal error) and its folder exactly as it was — the
// inputs untouched, no partial output and no temporary file.
//
// One row of kCases is one case: a name, what to write into the case's folder (on top of the
// valid inputs every case starts with, see write_base_inputs), the arguments (run in that folder)
// and the text the error line must contain.
#include <elastolearn/io/hdf5_file.hpp>
#include <elastolearn/io/observation_file.hpp>
#include <elastolearn/io/springs_scene.hpp>
#include <elastolearn/io/trajectory_file.hpp>
#include <elastolearn/mesh/primitives.hpp>

#include <support/cli_runner.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace elastolearn;
namespace h5 = elastolearn::io::h5;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- valid inputs every case starts from ------------------------------------------------------

/// A bar of 2 × 1 × 1 cells (12 vertices), 5 steps of 2 ms.
const char* kScene = R"({
  "format": "elastolearn-scene/1",
  "mesh": {"type": "box", "size": [0.2, 0.05, 0.05], "cells": [2, 1, 1]},
  "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000},
  "gravity": [0, -9.81, 0],
  "fixed": [{"min": "x"}],
  "time": {"dt": 0.002, "frames": 5}
})";

const char* kMaterial = R"({"format": "elastolearn-material/1",
  "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000}})";

/// One camera looking at the bar of kScene from above.
const char* kTopCamera = R"({"format": "elastolearn-cameras/1", "cameras": [{"name": "top",
  "position": [0.1, 0.5, 0.025], "look_at": [0.1, 0, 0.025], "up": [0, 0, -1],
  "resolution": [16, 12], "fov_y": 40}]})";

/// One positively oriented tet.
const char* kNode = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
const char* kEle = "1 4 0\n0 0 1 2 3\n";
const char* kOff = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

const char* kSprings = R"({
  "format": "elastolearn-springs-scene/1",
  "system": {"type": "rope", "nodes": 4},
  "spring": {"law": "linear", "k": 500, "c": 1},
  "simulation": {"mode": "explicit", "dt": 0.01, "steps": 10}
})";

/// A scene of `kScene` with its "mesh" or "material" (JSON text) replaced.
std::string scene_with(const std::string& key, const std::string& value) {
  std::string text = kScene;
  const auto begin = text.find("\"" + key + "\"");
  const auto end = text.find('\n', begin);
  text.replace(begin, end - begin, "\"" + key + "\": " + value + ",");
  return text;
}

/// `text` with its first `from` replaced by `to`.
std::string edit(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}
std::string scene_edit(const std::string& from, const std::string& to) {
  return edit(kScene, from, to);
}
std::string springs_edit(const std::string& from, const std::string& to) {
  return edit(kSprings, from, to);
}

void write_text(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return { std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>() };
}

/// Shapes and values of a trajectory or observation file, written without validation.
struct H5Spec {
  std::map<std::string, std::pair<h5::Shape, std::vector<double>>> f64;
  std::map<std::string, std::pair<h5::Shape, std::vector<int>>> i32;
  std::map<std::string, std::string> attributes;
};

/// A valid one-tet trajectory, 3 frames of 10 ms.
H5Spec trajectory_spec() {
  H5Spec s;
  const std::vector<double> rest = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  std::vector<double> frames;
  for (int t = 0; t < 3; ++t)
    for (double v : rest)
      frames.push_back(v + 0.01 * t);
  s.f64["/rest_positions"] = { { 4, 3 }, rest };
  s.f64["/positions"] = { { 3, 4, 3 }, frames };
  s.f64["/time"] = { { 3 }, { 0, 0.01, 0.02 } };
  s.i32["/tets"] = { { 1, 4 }, { 0, 1, 2, 3 } };
  s.attributes["format"] = "elastolearn-trajectory/1";
  return s;
}

/// A valid observation of vertices 0 and 1, 3 frames of 10 ms.
H5Spec observation_spec() {
  H5Spec s;
  s.i32["/observed/vertex_ids"] = { { 2 }, { 0, 1 } };
  s.f64["/observed/positions"] = { { 3, 2, 3 }, std::vector<double>(18, 0.5) };
  s.f64["/time"] = { { 3 }, { 0, 0.01, 0.02 } };
  s.attributes["format"] = "elastolearn-observation/1";
  s.attributes["dt"] = "0.01";
  return s;
}

/// A valid point-cloud file: 3 points in 2 frames of 10 ms (the second frame empty).
H5Spec clouds_spec() {
  H5Spec s;
  s.f64["/clouds/points"] = { { 3, 3 }, { 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0 } };
  s.i32["/clouds/offsets"] = { { 3 }, { 0, 3, 3 } };
  s.f64["/time"] = { { 2 }, { 0, 0.01 } };
  s.attributes["format"] = "elastolearn-clouds/1";
  s.attributes["dt"] = "0.01";
  return s;
}

void write_h5(const fs::path& path, const H5Spec& spec) {
  h5::File file = h5::File::create(path);
  for (const auto& [name, data] : spec.f64)
    file.write(name, data.second.data(), data.first);
  for (const auto& [name, data] : spec.i32)
    file.write(name, data.second.data(), data.first);
  for (const auto& [name, value] : spec.attributes)
    file.set_attribute(name, value);
  file.close();
}

/// An HDF5 file whose `dataset` declares `shape` (float64, chunked) but stores no data: a
/// tiny file that claims to hold billions of values.
void write_h5_huge(
    const fs::path& path, const H5Spec& spec, const std::string& dataset, const h5::Shape& shape) {
  H5Spec rest = spec;
  rest.f64.erase(dataset);
  rest.i32.erase(dataset);
  write_h5(path, rest);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t space = H5Screate_simple(int(shape.size()), shape.data(), nullptr);
  const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
  h5::Shape chunk(shape.size(), 1);
  chunk.back() = shape.back();
  H5Pset_chunk(plist, int(chunk.size()), chunk.data());
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  const hid_t ds
      = H5Dcreate2(file, dataset.c_str(), H5T_IEEE_F64LE, space, lcpl, plist, H5P_DEFAULT);
  H5Dclose(ds);
  H5Pclose(lcpl);
  H5Pclose(plist);
  H5Sclose(space);
  H5Fclose(file);
}

/// Valid inputs of every case, made once: scenes (inline mesh, TetGen mesh file, material
/// file), a trajectory and an observation, a learned material and spring, a mesh, a surface,
/// a springs scene, a vertex list, a regular file to put impossible outputs under and a folder.
void write_base_inputs(const fs::path& dir) {
  fs::create_directories(dir / "folder");
  write_text(dir / "scene.json", kScene);
  write_text(dir / "mesh_scene.json", scene_with("mesh", R"({"file": "mesh.node"})"));
  write_text(dir / "mat_scene.json", scene_with("material", R"("learned.json")"));
  write_text(dir / "learned.json", kMaterial);
  write_text(dir / "mesh.node", kNode);
  write_text(dir / "mesh.ele", kEle);
  write_text(dir / "surface.off", kOff);
  write_text(dir / "springs.json", kSprings);
  write_text(dir / "ids.txt", "0 1\n");
  write_text(dir / "notadir", "a regular file: nothing can be created under it\n");
  write_text(dir / "cam.json", kTopCamera);
  write_text(dir / "frames/frame_1.xyz", "0 0 0\n0.1 0 0\n");
  write_text(dir / "frames/frame_2.xyz", "0 0 0.1\n");
  fs::create_directories(dir / "empty");

  // The scene's own trajectory (12 vertices, 6 frames) and an observation of it.
  const mesh::TetMesh bar = mesh::make_box_bar(Vec3(0.2, 0.05, 0.05), { 2, 1, 1 });
  io::TrajectoryData traj;
  traj.rest_positions = bar.rest_positions();
  traj.tets = bar.tets();
  observe::Observation obs;
  obs.vertex_ids = { 0, 5, 11 };
  obs.dt = 0.002;
  for (int t = 0; t <= 5; ++t) {
    Positions p = bar.rest_positions();
    p.col(1).array() -= 1e-4 * t * p.col(0).array();
    traj.positions.push_back(p);
    traj.time.push_back(0.002 * t);
    Positions o(3, 3);
    for (int j = 0; j < 3; ++j)
      o.row(j) = p.row(obs.vertex_ids[std::size_t(j)]);
    obs.positions.push_back(o);
  }
  io::write_trajectory_h5(dir / "traj.h5", traj);
  io::write_observation_h5(dir / "obs.h5", obs);
  write_h5(dir / "clouds.h5", clouds_spec());

  springs::TrainingOptions training;
  training.steps = 50;
  io::write_learned_spring(dir / "spring.json", springs::learn_spring(training));
  std::string model_scene = kSprings;
  const std::string law = R"({"law": "linear", "k": 500, "c": 1})";
  model_scene.replace(model_scene.find(law), law.size(), R"({"model": "spring.json"})");
  write_text(dir / "springs_model.json", model_scene);
}

// ---- what a case writes -----------------------------------------------------------------------

using Maker = std::function<void(const fs::path& dir)>;

Maker nothing() {
  return [](const fs::path&) {};
}
Maker text(const std::string& name, const std::string& contents) {
  return [=](const fs::path& dir) { write_text(dir / name, contents); };
}
Maker both(Maker a, Maker b) {
  return [=](const fs::path& dir) { a(dir), b(dir); };
}
/// The first `bytes` bytes of a base input (negative: all but the last -bytes).
Maker truncated(const std::string& name, const std::string& of, long bytes) {
  return [=](const fs::path& dir) {
    std::string data = read_bytes(dir / of);
    data.resize(std::size_t(bytes >= 0 ? bytes : long(data.size()) + bytes));
    write_text(dir / name, data);
  };
}
/// A base input with bytes from `offset` on overwritten by a pseudo-random pattern.
Maker garbled(const std::string& name, const std::string& of, std::size_t offset) {
  return [=](const fs::path& dir) {
    std::string data = read_bytes(dir / of);
    std::uint32_t x = 2463534242u;
    for (std::size_t i = offset; i < data.size(); ++i) {
      x ^= x << 13, x ^= x >> 17, x ^= x << 5;
      data[i] = char(x & 0xff);
    }
    write_text(dir / name, data);
  };
}
Maker symlink(const std::string& name, const std::string& to) {
  return [=](const fs::path& dir) { fs::create_symlink(to, dir / name); };
}
Maker hardlink(const std::string& name, const std::string& to) {
  return [=](const fs::path& dir) { fs::create_hard_link(dir / to, dir / name); };
}
Maker trajectory(const std::string& name, std::function<void(H5Spec&)> edit) {
  return [=](const fs::path& dir) {
    H5Spec s = trajectory_spec();
    edit(s);
    write_h5(dir / name, s);
  };
}
Maker observation(const std::string& name, std::function<void(H5Spec&)> edit) {
  return [=](const fs::path& dir) {
    H5Spec s = observation_spec();
    edit(s);
    write_h5(dir / name, s);
  };
}
Maker clouds(const std::string& name, std::function<void(H5Spec&)> edit) {
  return [=](const fs::path& dir) {
    H5Spec s = clouds_spec();
    edit(s);
    write_h5(dir / name, s);
  };
}
Maker huge(
    const std::string& name, H5Spec (*spec)(), const std::string& dataset, const h5::Shape& shape) {
  return [=](const fs::path& dir) { write_h5_huge(dir / name, spec(), dataset, shape); };
}
/// 4096 bytes of pseudo-random data.
std::string noise() {
  std::string data(4096, '\0');
  std::uint32_t x = 88675123u;
  for (char& c : data) {
    x ^= x << 13, x ^= x >> 17, x ^= x << 5;
    c = char(x & 0xff);
  }
  return data;
}
/// A binary STL: 80-byte header, a triangle count, then `triangles` records of 50 bytes.
std::string binary_stl(std::uint32_t claimed, int triangles) {
  std::string data(80, ' ');
  data.append(reinterpret_cast<const char*>(&claimed), 4);
  data.append(std::size_t(50 * triangles), '\0');
  return data;
}

const std::string kGmshHeader = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
const std::string kGmshNodes = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
std::string gmsh(const std::string& nodes, const std::string& element) {
  return kGmshHeader + nodes + "$Elements\n1\n" + element + "\n$EndElements\n";
}
const std::string kVegVertices = "*VERTICES\n4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
std::string veg(const std::string& vertices, const std::string& element) {
  return vertices + "*ELEMENTS\nTET\n1 4 0\n" + element + "\n";
}
const std::string kPlyHeader
    = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty "
      "float y\nproperty float z\nelement face 1\nproperty list uchar int "
      "vertex_indices\nend_header\n";
const std::string kPlyVertices = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
/// A point-cloud PLY header for two points (the body follows on lines 8 and 9).
const std::string kPlyCloudHeader = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                    "property float y\nproperty float z\nend_header\n";

struct Case {
  std::string name; ///< unique, says what is hostile
  Maker make; ///< writes the hostile file(s) into the case folder
  std::string args; ///< elastolearn's arguments, run in the case folder
  std::vector<std::string> expect; ///< each must appear in the error line
};

const std::string kReplace = "would replace the input";
// Commands up to the file a case replaces: kLearn + "obs.h5 -o out.json".
const std::string kLearn = "learn scene.json -q --observations ";
const std::string kFit = "fit-parameters scene.json -q --observations ";
const std::string kEvaluate = "evaluate scene.json -q --material learned.json --truth ";

// clang-format off
const std::vector<Case> kCases = {
  // ---- scene JSON ---------------------------------------------------------------------------
  { "scene_empty", text("s.json", ""), "simulate s.json -o out.h5", { "s.json", "invalid JSON" } },
  { "scene_truncated", truncated("s.json", "scene.json", 60), "simulate s.json -o out.h5", { "s.json:" } },
  { "scene_garbled", garbled("s.json", "scene.json", 20), "simulate s.json -o out.h5", { "s.json:" } },
  { "scene_binary", text("s.json", noise()), "info s.json", { "s.json" } },
  { "scene_not_an_object", text("s.json", "[1, 2]"), "simulate s.json -o out.h5", { "s.json" } },
  { "scene_deep_nesting", text("s.json", std::string(100000, '[') + std::string(100000, ']')), "simulate s.json -o out.h5", { "s.json" } },
  { "scene_unknown_key", text("s.json", scene_edit("\"poisson\"", "\"poison\"")), "simulate s.json -o out.h5", { "s.json", "poison" } },
  { "scene_infinite_young", text("s.json", scene_edit("1e5", "1e999")), "simulate s.json -o out.h5", { "s.json:4:", "1e999" } },
  { "scene_nan_as_string", text("s.json", scene_edit("1e5", "\"NaN\"")), "simulate s.json -o out.h5", { "s.json", "material.young" } },
  { "scene_negative_dt", text("s.json", scene_edit("0.002", "-0.002")), "simulate s.json -o out.h5", { "s.json", "time.dt" } },
  { "scene_frames_beyond_int", text("s.json", scene_edit("\"frames\": 5", "\"frames\": 1e12")), "simulate s.json -o out.h5", { "s.json", "time.frames" } },
  { "scene_huge_box", text("s.json", scene_edit("[2, 1, 1]", "[100000, 100000, 100000]")), "simulate s.json -o out.h5", { "s.json", "mesh.cells" } },
  { "scene_int_max_cells", text("s.json", scene_edit("[2, 1, 1]", "[2147483647, 1, 1]")), "simulate s.json -o out.h5", { "s.json", "mesh.cells" } },
  { "scene_huge_sphere", text("s.json", scene_with("mesh", R"({"type": "sphere", "radius": 1, "tets": 2000000000})")), "simulate s.json -o out.h5", { "s.json", "mesh.tets" } },
  { "scene_negative_vertex", text("s.json", scene_edit(R"({"min": "x"})", R"({"vertices": [-1]})")), "simulate s.json -o out.h5", { "s.json", "fixed[0].vertices" } },
  { "scene_vertex_out_of_range", text("s.json", scene_edit(R"({"min": "x"})", R"({"vertices": [12]})")), "simulate s.json -o out.h5", { "s.json", "fixed[0].vertices" } },
  { "scene_wrong_type", text("s.json", scene_edit(R"("gravity": [0, -9.81, 0])", R"("gravity": "down")")), "simulate s.json -o out.h5", { "s.json", "gravity" } },
  { "scene_missing_mesh_file", text("s.json", scene_with("mesh", R"({"file": "nope.node"})")), "simulate s.json -o out.h5", { "nope" } },
  { "scene_missing_material_file", text("s.json", scene_with("material", R"("nope.json")")), "simulate s.json -o out.h5", { "s.json", "nope.json" } },
  { "scene_material_is_folder", text("s.json", scene_with("material", R"("folder")")), "simulate s.json -o out.h5", { "s.json", "material" } },
  { "scene_mesh_is_garbage", both(text("s.json", scene_with("mesh", R"({"file": "g.msh"})")), text("g.msh", noise())), "simulate s.json -o out.h5", { "g.msh" } },
  { "scene_future_format", text("s.json", scene_edit("elastolearn-scene/1", "elastolearn-scene/99")), "simulate s.json -o out.h5", { "s.json", "format" } },
  { "scene_is_a_folder", nothing(), "simulate folder -o out.h5", { "folder", "not a file" } },
  { "scene_missing", nothing(), "simulate nope.json -o out.h5", { "nope.json" } },
  { "info_scene_unknown_key", text("s.json", scene_edit("\"gravity\"", "\"gravitty\"")), "info s.json", { "s.json", "gravitty" } },

  // ---- learned material JSON ----------------------------------------------------------------
  { "material_empty", text("m.json", ""), "simulate scene.json --material m.json -o out.h5", { "m.json" } },
  { "material_truncated", truncated("m.json", "learned.json", 30), "simulate scene.json --material m.json -o out.h5", { "m.json:" } },
  { "material_wrong_format", text("m.json", R"({"format": "elastolearn-scene/1"})"), "evaluate scene.json --material m.json --truth traj.h5", { "m.json", "format" } },
  { "material_unknown_key", text("m.json", R"({"format": "elastolearn-material/1", "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000}, "colour": 1})"), "simulate scene.json --material m.json -o out.h5", { "m.json", "colour" } },
  { "material_nan_poisson", text("m.json", R"({"format": "elastolearn-material/1", "material": {"model": "corotated", "young": 1e5, "poisson": 1e999, "density": 1000}})"), "info m.json", { "m.json:", "1e999" } },
  { "material_bad_correction", text("m.json", R"({"format": "elastolearn-material/1", "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000}, "correction": {"type": "rbf", "centres": [[1, 1, 1]], "weights": []}})"), "simulate scene.json --material m.json -o out.h5", { "m.json", "correction" } },
  { "material_infinite_bias", text("m.json", R"({"format": "elastolearn-material/1", "material": {"model": "corotated", "young": 1e5, "poisson": 0.3, "density": 1000}, "correction": {"type": "nn", "input_mean": [0,0,0,0,0,0], "input_scale": [1,1,1,1,1,1], "output_mean": 0, "output_scale": 1, "layers": [{"weight": [[1,1,1,1,1,1]], "bias": [1e999]}]}})"), "info m.json", { "m.json:", "1e999" } },
  { "material_binary", text("m.json", noise()), "info m.json", { "m.json" } },

  // ---- trajectory HDF5 ----------------------------------------------------------------------
  { "trajectory_empty", text("t.h5", ""), "observe t.h5 --visible-fraction 0.5 -o out.h5", { "t.h5" } },
  { "trajectory_truncated", truncated("t.h5", "traj.h5", -200), "observe t.h5 --visible-fraction 0.5 -o out.h5", { "t.h5" } },
  { "trajectory_garbled", garbled("t.h5", "traj.h5", 600), "observe t.h5 --visible-fraction 0.5 -o out.h5", { "t.h5" } },
  { "trajectory_text", text("t.h5", "not hdf5\n"), "info t.h5", { "t.h5" } },
  { "trajectory_no_format", trajectory("t.h5", [](H5Spec& s) { s.attributes.clear(); }), "info t.h5", { "t.h5", "format" } },
  { "trajectory_nan_position", trajectory("t.h5", [](H5Spec& s) { s.f64["/positions"].second[13] = kNaN; }), "observe t.h5 --visible-fraction 0.5 -o out.h5", { "t.h5", "/positions" } },
  { "trajectory_nan_rest", trajectory("t.h5", [](H5Spec& s) { s.f64["/rest_positions"].second[0] = kNaN; }), "info t.h5", { "t.h5", "/rest_positions" } },
  { "trajectory_negative_tet_index", trajectory("t.h5", [](H5Spec& s) { s.i32["/tets"].second[2] = -1; }), "observe t.h5 --visible-fraction 0.5 -o out.h5", { "t.h5", "/tets" } },
  { "trajectory_tet_index_too_big", trajectory("t.h5", [](H5Spec& s) { s.i32["/tets"].second[2] = 4; }), "info t.h5", { "t.h5", "/tets" } },
  { "trajectory_inverted_tet", trajectory("t.h5", [](H5Spec& s) { s.i32["/tets"].second = { 0, 2, 1, 3 }; }), "observe t.h5 --visible-fraction 0.5 -o out.h5", { "t.h5" } },
  { "trajectory_wrong_shape", trajectory("t.h5", [](H5Spec& s) { s.f64["/positions"].first = { 3, 6, 2 }; }), "info t.h5", { "t.h5", "/positions" } },
  { "trajectory_time_backwards", trajectory("t.h5", [](H5Spec& s) { s.f64["/time"].second = { 0, 0.02, 0.01 }; }), "info t.h5", { "t.h5", "/time" } },
  { "trajectory_huge_positions", huge("t.h5", trajectory_spec, "/positions", { 1000000000, 4, 3 }), "info t.h5", { "t.h5", "/positions" } },
  { "trajectory_huge_rest", huge("t.h5", trajectory_spec, "/rest_positions", { 4000000000, 3 }), "observe t.h5 --visible-fraction 0.5 -o out.h5", { "t.h5", "/rest_positions" } },
  { "trajectory_is_an_observation", nothing(), "observe obs.h5 --visible-fraction 0.5 -o out.h5", { "obs.h5", "trajectory" } },
  { "truth_garbled", garbled("t.h5", "traj.h5", 600), kEvaluate + "t.h5", { "t.h5" } },
  { "truth_of_another_mesh", trajectory("t.h5", [](H5Spec&) { }), kEvaluate + "t.h5", { "t.h5", "/rest_positions" } },
  { "vertex_list_negative", text("v.txt", "0 -1\n"), "observe traj.h5 --vertices v.txt -o out.h5", { "v.txt:1" } },
  { "vertex_list_huge", text("v.txt", "0 99999999999\n"), "observe traj.h5 --vertices v.txt -o out.h5", { "v.txt:1" } },

  // ---- observation HDF5 ---------------------------------------------------------------------
  { "observation_empty", text("o.h5", ""), kLearn + "o.h5 -o out.json", { "o.h5" } },
  { "observation_truncated", truncated("o.h5", "obs.h5", -100), kFit + "o.h5 -o out.json", { "o.h5" } },
  { "observation_garbled", garbled("o.h5", "obs.h5", 500), "info o.h5", { "o.h5" } },
  { "observation_nan", observation("o.h5", [](H5Spec& s) { s.f64["/observed/positions"].second[4] = kNaN; }), "info o.h5", { "o.h5", "/observed/positions" } },
  { "observation_negative_id", observation("o.h5", [](H5Spec& s) { s.i32["/observed/vertex_ids"].second[1] = -3; }), kLearn + "o.h5 -o out.json", { "o.h5", "/observed/vertex_ids" } },
  { "observation_duplicate_id", observation("o.h5", [](H5Spec& s) { s.i32["/observed/vertex_ids"].second[1] = 0; }), "info o.h5", { "o.h5", "/observed/vertex_ids" } },
  { "observation_id_beyond_mesh", observation("o.h5", [](H5Spec& s) { s.i32["/observed/vertex_ids"].second[1] = 1000; }), kFit + "o.h5 -o out.json", { "o.h5" } },
  { "observation_dt_missing", observation("o.h5", [](H5Spec& s) { s.attributes.erase("dt"); }), "info o.h5", { "o.h5", "dt" } },
  { "observation_dt_nan", observation("o.h5", [](H5Spec& s) { s.attributes["dt"] = "nan"; }), "info o.h5", { "o.h5", "dt" } },
  { "observation_huge", huge("o.h5", observation_spec, "/observed/positions", { 1000000000, 2, 3 }), kLearn + "o.h5 -o out.json", { "o.h5", "/observed/positions" } },
  { "observation_valid_wrong_shape", observation("o.h5", [](H5Spec& s) { s.i32["/observed/valid"] = { { 2, 3 }, { 1, 1, 1, 1, 1, 1 } }; }), "info o.h5", { "o.h5", "/observed/valid", "(3, 2)" } },
  { "observation_valid_not_0_or_1", observation("o.h5", [](H5Spec& s) { s.i32["/observed/valid"] = { { 3, 2 }, { 1, 1, 1, 7, 1, 1 } }; }), kFit + "o.h5 -o out.json", { "o.h5", "/observed/valid", "value 7" } },
  { "observation_valid_float", observation("o.h5", [](H5Spec& s) { s.f64["/observed/valid"] = { { 3, 2 }, { 1, 1, 1, 0, 1, 1 } }; }), kLearn + "o.h5 -o out.json", { "o.h5", "/observed/valid", "integers" } },
  { "observation_valid_all_lost", observation("o.h5", [](H5Spec& s) { s.i32["/observed/valid"] = { { 3, 2 }, { 0, 0, 0, 0, 0, 0 } }; }), "info o.h5", { "o.h5", "/observed/valid", "every entry is 0" } },
  { "observation_nan_where_seen", observation("o.h5", [](H5Spec& s) { s.i32["/observed/valid"] = { { 3, 2 }, { 1, 1, 0, 1, 1, 1 } }; s.f64["/observed/positions"].second[4] = kNaN; }), kFit + "o.h5 -o out.json", { "o.h5", "/observed/positions", "marks as seen" } },
  { "observation_is_a_trajectory", nothing(), kLearn + "traj.h5 -o out.json", { "traj.h5", "observation" } },
  { "observation_frames_differ_from_scene", observation("o.h5", [](H5Spec&) { }), kLearn + "o.h5 -o out.json", { "o.h5" } },
  { "checkpoint_garbled_on_resume", text("out.json.checkpoint.json", "{\"format\": "), kLearn + "obs.h5 -o out.json --resume", { "out.json.checkpoint.json:1:" } },

  // ---- point clouds: HDF5, per-frame PLY/XYZ folders, cameras, scans -------------------------
  { "clouds_nan", clouds("c.h5", [](H5Spec& s) { s.f64["/clouds/points"].second[4] = kNaN; }), "info c.h5", { "c.h5: /clouds/points", "frame 0, point 1", "non-finite" } },
  { "clouds_frame_count_mismatch", clouds("c.h5", [](H5Spec& s) { s.f64["/time"] = { { 3 }, { 0, 0.01, 0.02 } }; }), "info c.h5", { "c.h5: /time", "3 frames", "/clouds/offsets" } },
  { "clouds_offsets_decrease", clouds("c.h5", [](H5Spec& s) { s.i32["/clouds/offsets"].second = { 0, 3, 2 }; }), "info c.h5", { "c.h5: /clouds/offsets" } },
  { "clouds_offsets_beyond_points", clouds("c.h5", [](H5Spec& s) { s.i32["/clouds/offsets"].second = { 0, 3, 2000000000 }; }), "info c.h5", { "c.h5: /clouds/offsets" } },
  { "clouds_normals_not_unit", clouds("c.h5", [](H5Spec& s) { s.f64["/clouds/normals"] = { { 3, 3 }, std::vector<double>(9, 255) }; }), "info c.h5", { "c.h5: /clouds/normals", "not a unit vector" } },
  { "clouds_dt_missing", clouds("c.h5", [](H5Spec& s) { s.attributes.erase("dt"); }), "info c.h5", { "c.h5", "dt" } },
  { "clouds_huge", huge("c.h5", clouds_spec, "/clouds/points", { 4000000000, 3 }), "info c.h5", { "c.h5", "/clouds/points" } },
  { "clouds_truncated", truncated("c.h5", "clouds.h5", -100), "info c.h5", { "c.h5" } },
  { "clouds_garbled", garbled("c.h5", "clouds.h5", 500), "info c.h5", { "c.h5" } },
  { "import_empty_folder", nothing(), "import-clouds empty --dt 0.01 -o out.h5", { "empty", "no .ply or .xyz files" } },
  { "import_missing_folder", nothing(), "import-clouds nope --dt 0.01 -o out.h5", { "nope", "no such folder" } },
  { "import_folder_is_a_file", nothing(), "import-clouds notadir --dt 0.01 -o out.h5", { "notadir", "not a folder" } },
  { "import_bad_xyz_line", text("frames/frame_10.xyz", "0 0 0\n1 one 2\n"), "import-clouds frames --dt 0.01 -o out.h5", { "frame_10.xyz:2", "'one'" } },
  { "import_nan_xyz", text("frames/frame_3.xyz", "nan 0 0\n"), "import-clouds frames --dt 0.01 -o out.h5", { "frame_3.xyz:1", "non-finite x" } },
  { "import_colours_as_normals", text("frames/frame_3.xyz", "0 0 0 255 0 0\n"), "import-clouds frames --dt 0.01 -o out.h5", { "frame_3.xyz:1", "not a unit vector" } },
  { "import_nan_ply", text("frames/frame_3.ply", kPlyCloudHeader + "0 0 0\n0 nan 1\n"), "import-clouds frames --dt 0.01 -o out.h5", { "frame_3.ply:9", "non-finite y" } },
  { "import_ply_huge_count", text("frames/frame_3.ply", edit(kPlyCloudHeader, "vertex 2", "vertex 2000000000") + "0 0 0\n"), "import-clouds frames --dt 0.01 -o out.h5", { "frame_3.ply", "end of file" } },
  { "import_ply_binary_truncated", text("frames/frame_3.ply", edit(kPlyCloudHeader, "ascii", "binary_little_endian") + std::string(20, '\0')), "import-clouds frames --dt 0.01 -o out.h5", { "frame_3.ply", "truncated" } },
  { "import_ply_garbage", text("frames/frame_3.ply", noise()), "import-clouds frames --dt 0.01 -o out.h5", { "frame_3.ply" } },
  { "import_mixed_normals", text("frames/frame_3.xyz", "0 0 0 0 0 1\n"), "import-clouds frames --dt 0.01 -o out.h5", { "frame_3.xyz", "has normals", "have none" } },
  { "import_negative_dt", nothing(), "import-clouds frames --dt -0.01 -o out.h5", { "--dt" } },
  { "import_output_is_a_frame", nothing(), "import-clouds frames --dt 0.01 -o frames/frame_2.xyz", { "frame_2.xyz", kReplace } },
  { "camera_empty", text("c.json", ""), "scan traj.h5 --camera c.json -o out.h5", { "c.json", "invalid JSON" } },
  { "camera_unknown_key", text("c.json", edit(kTopCamera, "\"up\"", "\"upp\"")), "scan traj.h5 --camera c.json -o out.h5", { "c.json: cameras[0].upp" } },
  { "camera_both_fov_and_intrinsics", text("c.json", edit(kTopCamera, "\"fov_y\": 40", "\"fov_y\": 40, \"intrinsics\": {\"fx\": 1, \"fy\": 1, \"cx\": 0, \"cy\": 0}")), "scan traj.h5 --camera c.json -o out.h5", { "c.json: cameras[0]", "exactly one" } },
  { "camera_infinite_position", text("c.json", edit(kTopCamera, "0.5", "1e999")), "scan traj.h5 --camera c.json -o out.h5", { "c.json:2:", "1e999" } },
  { "camera_huge_resolution", text("c.json", edit(kTopCamera, "[16, 12]", "[100000, 100000]")), "scan traj.h5 --camera c.json -o out.h5", { "c.json: cameras[0].resolution" } },
  { "camera_looks_at_itself", text("c.json", edit(kTopCamera, "[0.1, 0, 0.025]", "[0.1, 0.5, 0.025]")), "scan traj.h5 --camera c.json -o out.h5", { "c.json: cameras[0].look_at" } },
  { "scan_negative_noise", nothing(), "scan traj.h5 --camera cam.json --noise -1 -o out.h5", { "scan.noise" } },
  { "scan_outliers_above_one", nothing(), "scan traj.h5 --camera cam.json --outliers 2 -o out.h5", { "scan.outliers" } },
  { "scan_trajectory_without_surface", trajectory("t.h5", [](H5Spec& s) { s.i32.erase("/tets"); }), "scan t.h5 --camera cam.json -o out.h5", { "t.h5", "neither /tets nor /faces" } },
  { "scan_trajectory_nan", trajectory("t.h5", [](H5Spec& s) { s.f64["/positions"].second[13] = kNaN; }), "scan t.h5 --camera cam.json -o out.h5", { "t.h5", "/positions" } },
  { "scan_of_clouds", nothing(), "scan clouds.h5 --camera cam.json -o out.h5", { "clouds.h5", "trajectory" } },
  { "scan_output_is_trajectory", nothing(), "scan traj.h5 --camera cam.json -o traj.h5", { "traj.h5", kReplace } },
  { "scan_output_is_camera", nothing(), "scan traj.h5 --camera cam.json -o cam.json", { "cam.json", kReplace } },
  { "scan_output_under_file", nothing(), "scan traj.h5 --camera cam.json -o notadir/c.h5", { "notadir/c.h5", "not a folder" } },
  { "track_dt_differs_from_scene", nothing(), "track scene.json --clouds clouds.h5 -q -o out.h5", { "clouds.h5: dt", "0.002" } },
  { "track_clouds_nan", clouds("c.h5", [](H5Spec& s) { s.f64["/clouds/points"].second[4] = kNaN; }), "track scene.json --clouds c.h5 -q -o out.h5", { "c.h5: /clouds/points", "non-finite" } },
  { "track_noise_sigma_garbage", clouds("c.h5", [](H5Spec& s) { s.attributes["noise_sigma"] = "one mm"; }), "track scene.json --clouds c.h5 -q -o out.h5", { "c.h5", "noise_sigma", "'one mm'" } },
  { "track_negative_sigma", nothing(), "track scene.json --clouds clouds.h5 --sigma -1 -q -o out.h5", { "tracking.sigma" } },
  { "track_zero_weight", nothing(), "track scene.json --clouds clouds.h5 --sigma 0.001 --weight 0 -q -o out.h5", { "tracking.weight" } },
  { "track_trajectory_as_clouds", nothing(), "track scene.json --clouds traj.h5 -q -o out.h5", { "traj.h5" } },
  { "track_output_is_clouds", nothing(), "track scene.json --clouds clouds.h5 -q -o clouds.h5", { "clouds.h5", kReplace } },

  // ---- TetGen .node/.ele --------------------------------------------------------------------
  { "tetgen_empty_node", both(text("b.node", ""), text("b.ele", kEle)), "info b.node", { "b.node" } },
  { "tetgen_missing_ele", text("b.node", kNode), "info b.node", { "b.ele" } },
  { "tetgen_missing_node", text("b.ele", kEle), "info b.ele", { "b.node" } },
  { "tetgen_truncated_node", both(text("b.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n"), text("b.ele", kEle)), "info b.node", { "b.node:", "end of file" } },
  { "tetgen_nan", both(text("b.node", "4 3 0 0\n0 0 0 0\n1 nan 0 0\n2 0 1 0\n3 0 0 1\n"), text("b.ele", kEle)), "info b.node", { "b.node:3" } },
  { "tetgen_huge_count", both(text("b.node", "2000000000 3 0 0\n0 0 0 0\n"), text("b.ele", kEle)), "info b.node", { "b.node:" } },
  { "tetgen_count_beyond_int", both(text("b.node", "99999999999999 3 0 0\n0 0 0 0\n"), text("b.ele", kEle)), "info b.node", { "b.node:1" } },
  { "tetgen_negative_count", both(text("b.node", "-4 3 0 0\n"), text("b.ele", kEle)), "info b.node", { "b.node:1" } },
  { "tetgen_huge_attributes", both(text("b.node", "4 3 2000000000 0\n0 0 0 0\n"), text("b.ele", kEle)), "info b.node", { "b.node:" } },
  { "tetgen_negative_index", both(text("b.node", kNode), text("b.ele", "1 4 0\n0 0 1 -2 3\n")), "info b.ele", { "b.ele:2" } },
  { "tetgen_index_out_of_range", both(text("b.node", kNode), text("b.ele", "1 4 0\n0 0 1 2 7\n")), "info b.node", { "b.ele:2" } },
  { "tetgen_inverted", both(text("b.node", kNode), text("b.ele", "1 4 0\n0 0 2 1 3\n")), "info b.node", { "b.ele" } },
  { "tetgen_garbled", both(text("b.node", noise()), text("b.ele", noise())), "info b.node", { "b.node" } },
  { "scene_mesh_inverted", both(both(text("b.node", kNode), text("b.ele", "1 4 0\n0 0 2 1 3\n")), text("s.json", scene_with("mesh", R"({"file": "b.node"})"))), "simulate s.json -o out.h5", { "b.ele" } },

  // ---- Gmsh .msh ----------------------------------------------------------------------------
  { "gmsh_empty", text("b.msh", ""), "info b.msh", { "b.msh" } },
  { "gmsh_truncated", text("b.msh", kGmshHeader + "$Nodes\n4\n1 0 0 0\n"), "info b.msh", { "b.msh:" } },
  { "gmsh_nan", text("b.msh", gmsh("$Nodes\n4\n1 0 0 0\n2 1 0 nan\n3 0 1 0\n4 0 0 1\n$EndNodes\n", "1 4 2 0 1 1 2 3 4")), "info b.msh", { "b.msh:7" } },
  { "gmsh_huge_count", text("b.msh", kGmshHeader + "$Nodes\n2000000000\n1 0 0 0\n"), "info b.msh", { "b.msh:" } },
  { "gmsh_unknown_node", text("b.msh", gmsh(kGmshNodes, "1 4 2 0 1 1 2 3 99")), "info b.msh", { "b.msh:" } },
  { "gmsh_negative_node", text("b.msh", gmsh(kGmshNodes, "1 4 2 0 1 1 2 3 -4")), "info b.msh", { "b.msh:" } },
  { "gmsh_inverted", text("b.msh", gmsh(kGmshNodes, "1 4 2 0 1 1 3 2 4")), "info b.msh", { "b.msh" } },
  { "gmsh_binary", text("b.msh", "$MeshFormat\n2.2 1 8\n" + noise()), "info b.msh", { "b.msh:" } },
  { "gmsh_garbled", text("b.msh", noise()), "info b.msh", { "b.msh" } },
  { "gmsh4_huge_block", text("b.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2000000000 1 2000000000\n3 1 0 2000000000\n1\n"), "info b.msh", { "b.msh:" } },

  // ---- Vega .veg ----------------------------------------------------------------------------
  { "vega_empty", text("b.veg", ""), "info b.veg", { "b.veg" } },
  { "vega_nan", text("b.veg", veg("*VERTICES\n4 3 0 0\n1 0 0 0\n2 inf 0 0\n3 0 1 0\n4 0 0 1\n", "1 1 2 3 4")), "info b.veg", { "b.veg:" } },
  { "vega_huge_count", text("b.veg", "*VERTICES\n2000000000 3 0 0\n1 0 0 0\n"), "info b.veg", { "b.veg:" } },
  { "vega_index_out_of_range", text("b.veg", veg(kVegVertices, "1 1 2 3 5")), "info b.veg", { "b.veg:" } },
  { "vega_negative_index", text("b.veg", veg(kVegVertices, "1 1 2 3 -1")), "info b.veg", { "b.veg:" } },
  { "vega_inverted", text("b.veg", veg(kVegVertices, "1 1 3 2 4")), "info b.veg", { "b.veg" } },
  { "vega_truncated", text("b.veg", "*VERTICES\n4 3 0 0\n1 0 0 0\n"), "info b.veg", { "b.veg" } },

  // ---- surfaces: OBJ, OFF, PLY, STL ---------------------------------------------------------
  { "obj_empty", text("b.obj", ""), "info b.obj", { "b.obj" } },
  { "obj_nan", text("b.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "info b.obj", { "b.obj:2" } },
  { "obj_index_zero", text("b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), "info b.obj", { "b.obj:4" } },
  { "obj_negative_out_of_range", text("b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -9\n"), "tetrahedralize b.obj -o out.node", { "b.obj:4" } },
  { "obj_index_out_of_range", text("b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n"), "info b.obj", { "b.obj:4" } },
  { "obj_garbled", text("b.obj", noise()), "info b.obj", { "b.obj" } },
  { "off_empty", text("b.off", ""), "tetrahedralize b.off -o out.node", { "b.off" } },
  { "off_huge_count", text("b.off", "OFF\n2000000000 4 0\n0 0 0\n"), "info b.off", { "b.off:" } },
  { "off_nan", text("b.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"), "info b.off", { "b.off:4" } },
  { "off_negative_index", text("b.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"), "info b.off", { "b.off:6" } },
  { "off_truncated", truncated("b.off", "surface.off", 40), "info b.off", { "b.off:" } },
  { "ply_empty", text("b.ply", ""), "info b.ply", { "b.ply" } },
  { "ply_huge_count", text("b.ply", "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n"), "info b.ply", { "b.ply" } },
  { "ply_index_out_of_range", text("b.ply", kPlyHeader + kPlyVertices + "3 0 1 9\n"), "info b.ply", { "b.ply" } },
  { "ply_negative_index", text("b.ply", kPlyHeader + kPlyVertices + "3 0 1 -1\n"), "info b.ply", { "b.ply" } },
  { "ply_nan", text("b.ply", kPlyHeader + "0 0 0\nnan 0 0\n0 1 0\n0 0 1\n3 0 1 2\n"), "info b.ply", { "b.ply" } },
  { "ply_binary_truncated", text("b.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\nproperty float z\nend_header\n" + std::string(20, '\0')), "info b.ply", { "b.ply" } },
  { "ply_garbled", text("b.ply", "ply\n" + noise()), "info b.ply", { "b.ply" } },
  { "stl_empty", text("b.stl", ""), "info b.stl", { "b.stl" } },
  { "stl_binary_huge_count", text("b.stl", binary_stl(0xffffffffu, 1)), "tetrahedralize b.stl -o out.node", { "b.stl" } },
  { "stl_binary_truncated", text("b.stl", binary_stl(10, 3)), "info b.stl", { "b.stl" } },
  { "stl_ascii_nan", text("b.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid x\n"), "info b.stl", { "b.stl:5" } },
  { "stl_ascii_truncated", text("b.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"), "info b.stl", { "b.stl" } },
  { "stl_garbled", text("b.stl", noise()), "info b.stl", { "b.stl" } },
  { "unknown_extension", text("b.xyz", "1 2 3\n"), "info b.xyz", { "b.xyz" } },
  { "info_of_a_folder", nothing(), "info folder", { "folder", "not a file" } },

  // ---- springs scenes and learned springs ---------------------------------------------------
  { "springs_empty", text("s.json", ""), "springs simulate s.json -o out.h5", { "s.json" } },
  { "springs_unknown_key", text("s.json", springs_edit("\"steps\"", "\"stepz\"")), "springs simulate s.json -o out.h5", { "s.json", "stepz" } },
  { "springs_huge_rope", text("s.json", springs_edit("\"nodes\": 4", "\"nodes\": 2000000000")), "springs simulate s.json -o out.h5", { "s.json", "system.nodes" } },
  { "springs_huge_cloth", text("s.json", springs_edit(R"({"type": "rope", "nodes": 4})", R"({"type": "cloth", "columns": 100000, "rows": 100000})")), "springs simulate s.json -o out.h5", { "s.json", "system" } },
  { "springs_infinite_k", text("s.json", springs_edit("500", "1e999")), "springs simulate s.json -o out.h5", { "s.json:", "1e999" } },
  { "springs_model_missing", text("s.json", springs_edit(R"({"law": "linear", "k": 500, "c": 1})", R"({"model": "nope.json"})")), "springs simulate s.json -o out.h5", { "nope.json" } },
  { "springs_model_garbled", garbled("spring.json", "spring.json", 10), "springs simulate springs_model.json -o out.h5", { "spring.json" } },
  { "springs_model_is_a_material", text("s.json", springs_edit(R"({"law": "linear", "k": 500, "c": 1})", R"({"model": "learned.json"})")), "springs simulate s.json -o out.h5", { "learned.json", "format" } },

  // ---- hostile command lines ----------------------------------------------------------------
  { "usage_no_command", nothing(), "", { "subcommand" } },
  { "usage_unknown_command", nothing(), "simulat scene.json", { "unknown command 'simulat'" } },
  { "usage_missing_output", nothing(), "observe traj.h5 --visible-fraction 0.5", { "--output" } },
  { "usage_unknown_option", nothing(), "simulate scene.json -o out.h5 --frobnicate", { "frobnicate" } },
  { "usage_not_a_number", nothing(), "observe traj.h5 --visible-fraction half -o out.h5", { "half" } },
  { "observe_fraction_nan", nothing(), "observe traj.h5 --visible-fraction nan -o out.h5", { "fraction" } },
  { "observe_fraction_negative", nothing(), "observe traj.h5 --visible-fraction -0.5 -o out.h5", { "fraction" } },
  { "observe_noise_negative", nothing(), "observe traj.h5 --visible-fraction 0.5 --noise -1 -o out.h5", { "noise" } },
  { "observe_noise_nan", nothing(), "observe traj.h5 --visible-fraction 0.5 --noise nan -o out.h5", { "noise" } },
  { "observe_dropout_one", nothing(), "observe traj.h5 --visible-fraction 0.5 --dropout 1 -o out.h5", { "dropout" } },
  { "observe_dropout_negative", nothing(), "observe traj.h5 --visible-fraction 0.5 --dropout -0.2 -o out.h5", { "dropout" } },
  { "observe_dropout_burst_short", nothing(), "observe traj.h5 --visible-fraction 0.5 --dropout 0.2 --dropout-burst 0.5 -o out.h5", { "dropout burst" } },
  { "learn_negative_iterations", nothing(), kLearn + "obs.h5 -o out.json --max-iterations -5", { "max" } },
  { "training_set_no_motions", text("set.json", R"({"format": "elastolearn-training/1", "motions": []})"), "learn set.json -q -o out.json", { "set.json", "motions" } },
  { "training_set_missing_observations", text("set.json", R"({"format": "elastolearn-training/1", "motions": [{"scene": "scene.json"}]})"), "learn set.json -q -o out.json", { "set.json", "motions[0]", "observations" } },
  { "training_set_observations_not_found", text("set.json", R"({"format": "elastolearn-training/1", "motions": [{"scene": "scene.json", "observations": "nope.h5"}]})"), "learn set.json -q -o out.json", { "nope.h5" } },
  { "training_set_unknown_key", text("set.json", R"({"format": "elastolearn-training/1", "motion": []})"), "learn set.json -q -o out.json", { "set.json", "motion" } },
  { "training_set_with_observations_option", text("set.json", R"({"format": "elastolearn-training/1", "motions": [{"scene": "scene.json", "observations": "obs.h5"}]})"), "learn set.json -q --observations obs.h5 -o out.json", { "--observations", "training set" } },
  { "learn_scene_without_observations", nothing(), "learn scene.json -q -o out.json", { "--observations" } },
  { "learn_output_is_training_set_observations", text("set.json", R"({"format": "elastolearn-training/1", "motions": [{"scene": "scene.json", "observations": "obs.h5"}]})"), "learn set.json -q -o obs.h5", { "obs.h5", kReplace } },
  { "learn_resume_without_checkpoint", nothing(), kLearn + "obs.h5 -o out.json --resume", { "checkpoint" } },
  { "fit_unknown_parameter", nothing(), kFit + "obs.h5 -o out.json --fit young,colour", { "colour" } },
  { "tetrahedralize_wrong_extension", nothing(), "tetrahedralize surface.off -o out.vtk", { "out.vtk" } },
  { "tetrahedralize_negative_tets", nothing(), "tetrahedralize surface.off -o out.node --max-tets -3", { "tets" } },
  { "springs_learn_nan_dt", nothing(), "springs learn --dt nan -o out.json", { "dt" } },
  { "springs_learn_negative_steps", nothing(), "springs learn --steps -1 -o out.json", { "steps" } },
  { "springs_learn_huge_degree", nothing(), "springs learn --degree 1000 -o out.json", { "degree" } },

  // ---- the output is one of the inputs ------------------------------------------------------
  { "observe_output_is_input", nothing(), "observe traj.h5 --visible-fraction 0.5 -o traj.h5", { "traj.h5", kReplace } },
  { "observe_output_spelled_differently", nothing(), "observe traj.h5 --visible-fraction 0.5 -o ./folder/../traj.h5", { "traj.h5", kReplace } },
  { "observe_output_symlink_to_input", symlink("link.h5", "traj.h5"), "observe traj.h5 --visible-fraction 0.5 -o link.h5", { "link.h5", kReplace } },
  { "observe_output_hardlink_to_input", hardlink("hard.h5", "traj.h5"), "observe traj.h5 --visible-fraction 0.5 -o hard.h5", { "hard.h5", kReplace } },
  { "observe_output_is_vertex_list", nothing(), "observe traj.h5 --vertices ids.txt -o ids.txt", { "ids.txt", kReplace } },
  { "simulate_output_is_scene", nothing(), "simulate scene.json -o scene.json", { "scene.json", kReplace } },
  { "simulate_output_is_mesh_node", nothing(), "simulate mesh_scene.json -o mesh.node", { "mesh.node", kReplace } },
  { "simulate_output_is_mesh_ele", nothing(), "simulate mesh_scene.json -o mesh.ele", { "mesh.ele", kReplace } },
  { "simulate_output_is_scene_material", nothing(), "simulate mat_scene.json -o learned.json", { "learned.json", kReplace } },
  { "simulate_output_is_material", nothing(), "simulate scene.json --material learned.json -o learned.json", { "learned.json", kReplace } },
  { "simulate_vtu_folder_is_scene", nothing(), "simulate scene.json -o out.h5 --vtu scene.json", { "scene.json", kReplace } },
  { "simulate_scene_output_is_scene", text("s.json", scene_edit("\"time\"", R"("output": {"trajectory": "s.json"}, "time")")), "simulate s.json", { "s.json", kReplace } },
  { "learn_output_is_observations", nothing(), kLearn + "obs.h5 -o obs.h5", { "obs.h5", kReplace } },
  { "learn_output_is_scene", nothing(), kLearn + "obs.h5 -o ./scene.json", { "scene.json", kReplace } },
  { "learn_checkpoint_is_scene", nothing(), kLearn + "obs.h5 -o out.json --checkpoint scene.json", { "scene.json", kReplace } },
  { "learn_report_holds_scene", text("report/report.json", kScene), "learn report/report.json --observations obs.h5 -o out.json --report report", { "report.json", kReplace } },
  { "learn_checkpoint_is_output", nothing(), kLearn + "obs.h5 -o out.json --checkpoint out.json", { "out.json", "same file" } },
  { "evaluate_output_is_truth", nothing(), kEvaluate + "traj.h5 -o traj.h5", { "traj.h5", kReplace } },
  { "evaluate_json_is_material", nothing(), kEvaluate + "traj.h5 --json learned.json", { "learned.json", kReplace } },
  { "evaluate_json_is_output", nothing(), kEvaluate + "traj.h5 --json out.h5 -o out.h5", { "out.h5", "same file" } },
  { "fit_output_is_observations", nothing(), kFit + "obs.h5 -o obs.h5", { "obs.h5", kReplace } },
  { "fit_output_is_scene_material", nothing(), "fit-parameters mat_scene.json --observations obs.h5 -o learned.json", { "learned.json", kReplace } },
  { "tetrahedralize_node_is_surface", symlink("s.node", "surface.off"), "tetrahedralize surface.off -o s.node", { "s.node", kReplace } },
  { "tetrahedralize_ele_is_surface", symlink("s.ele", "surface.off"), "tetrahedralize surface.off -o s.node", { "s.ele", kReplace } },
  { "springs_output_is_scene", nothing(), "springs simulate springs.json -o springs.json", { "springs.json", kReplace } },
  { "springs_output_is_learned_spring", nothing(), "springs simulate springs_model.json -o spring.json", { "spring.json", kReplace } },

  // ---- outputs that cannot be written -------------------------------------------------------
  { "simulate_output_under_file", nothing(), "simulate scene.json -o notadir/x.h5", { "notadir/x.h5", "not a folder" } },
  { "simulate_output_is_folder", nothing(), "simulate scene.json -o folder", { "folder", "is a folder" } },
  { "simulate_vtu_under_file", nothing(), "simulate scene.json -o out.h5 --vtu notadir/vtu", { "notadir/vtu", "not a folder" } },
  { "observe_output_under_file", nothing(), "observe traj.h5 --visible-fraction 0.5 -o notadir/o.h5", { "notadir/o.h5", "not a folder" } },
  { "learn_output_under_file", nothing(), kLearn + "obs.h5 -o notadir/m.json", { "notadir/m.json", "not a folder" } },
  { "learn_report_under_file", nothing(), kLearn + "obs.h5 -o out.json --report notadir/r", { "notadir/r", "not a folder" } },
  { "evaluate_json_under_file", nothing(), kEvaluate + "traj.h5 --json notadir/r.json", { "notadir/r.json", "not a folder" } },
  { "fit_output_under_file", nothing(), kFit + "obs.h5 -o notadir/deep/f.json", { "notadir/deep/f.json", "not a folder" } },
  { "tetrahedralize_output_under_file", nothing(), "tetrahedralize surface.off -o notadir/t.node", { "notadir/t.node", "not a folder" } },
  { "springs_learn_output_under_file", nothing(), "springs learn -o notadir/s.json", { "notadir/s.json", "not a folder" } },
  { "springs_simulate_output_under_file", nothing(), "springs simulate springs.json -o notadir/s.h5", { "notadir/s.h5", "not a folder" } },
  { "demo_folder_is_a_file", nothing(), "demo -o notadir", { "notadir", "not a folder" } },
  { "demo_folder_under_file", nothing(), "demo -o notadir/demo", { "notadir/demo", "not a folder" } },
  { "simulate_output_under_etc_passwd", nothing(), "simulate scene.json -o /etc/passwd/x.h5", { "/etc/passwd/x.h5" } },
  { "early_error_creates_no_folder", text("v.txt", "-1\n"), "observe traj.h5 --vertices v.txt -o new/deeper/o.h5", { "v.txt:1" } },
};
// clang-format on

/// Every entry under `dir` (recursively, symbolic links not followed): "f <bytes>" for a file,
/// "l <target>" for a link, "d" for a folder.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(e.path(), dir).string();
    if (e.is_symlink())
      out[name] = "l " + fs::read_symlink(e.path()).string();
    else if (e.is_directory())
      out[name] = "d";
    else
      out[name] = "f " + read_bytes(e.path());
  }
  return out;
}

class HostileInputs : public ::testing::Test {
  protected:
  static void SetUpTestSuite() {
    s_root = fs::temp_directory_path() / ("elastolearn_hostile_" + std::to_string(::getpid()));
    fs::remove_all(s_root);
    write_base_inputs(s_root / "base");
  }
  static void TearDownTestSuite() { fs::remove_all(s_root); }
  static fs::path s_root;
};

fs::path HostileInputs::s_root;

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif

TEST_F(HostileInputs, EveryCaseGivesOneErrorLineAnExitCodeAndLeavesItsFolderAsItWas) {
  std::map<std::string, int> names;
  for (const Case& c : kCases) {
    SCOPED_TRACE("case " + c.name + ": elastolearn " + c.args);
    ASSERT_EQ(names[c.name]++, 0) << "duplicate case name";
    const fs::path dir = s_root / c.name;
    fs::copy(s_root / "base", dir, fs::copy_options::recursive);
    c.make(dir);
    const auto before = snapshot(dir);
    // The memory limit turns an attempt to allocate what a hostile count claims into an error
    // instead of a machine-wide out-of-memory kill. AddressSanitizer reserves terabytes of
    // address space for its shadow memory, which a virtual-memory limit forbids: under it, its
    // allocator's own size checks stand in.
    const test::SplitRun r = test::run_split(c.args,
        "cd '" + dir.string() + "' && " + (kAddressSanitizer ? "" : "ulimit -v 4000000 &&"));
    EXPECT_TRUE(r.exit_code == 1 || r.exit_code == 2) << "exit code " << r.exit_code << "\n"
                                                      << r.err;
    const std::string& err = r.err;
    if (std::getenv("ELASTOLEARN_SHOW_ERRORS")) // to review the messages: every case's line
      std::printf("%-36s %s", c.name.c_str(), err.c_str());
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_EQ(err.rfind("elastolearn: error: ", 0), 0u) << err;
    EXPECT_EQ(std::count_if(err.begin(), err.end(),
                  [](char ch) { return (ch >= 0 && ch < 0x20 && ch != '\n') || ch == 0x7f; }),
        0)
        << "control characters in the error: " << err;
    for (const std::string& part : c.expect)
      EXPECT_NE(err.find(part), std::string::npos) << "the error lacks \"" << part << "\": " << err;
    EXPECT_EQ(snapshot(dir), before) << "the folder changed";
    fs::remove_all(dir);
  }
}

} // namespace
