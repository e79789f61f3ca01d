#include <elastolearn/core/error.hpp>
#include <elastolearn/core/format.hpp>
#include <elastolearn/learn/element_state.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>

namespace elastolearn::learn {

namespace {

constexpr FieldErrors element_state_error("stress_reconstruction");

/// Element states of elements [begin, end) (serial; no allocation), each frame the SVD of F at x
/// or, if `frames` is not null, its cached one.
void element_states_range(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    const fem::ElasticForce* frames, int begin, int end, std::vector<ElementState>& states) {
  for (int e = begin; e < end; ++e) {
    const fem::TetRestData& rest = mesh.rest[e];
    const Eigen::Vector4i tet = mesh.tets.row(e).transpose();
    ElementState& s = states[e];
    s.frame = frames != nullptr
        ? frames->cached_frame(e)
        : material::principal_frame(fem::deformation_gradient(fem::gather_tet(x, tet), rest));
    s.deformation_rate = fem::deformation_gradient(fem::gather_tet(v, tet), rest);
    s.stretch_rates = material::stretch_rates(s.frame, s.deformation_rate);
  }
}

void element_states(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    const fem::ElasticForce* frames, std::vector<ElementState>& states) {
  states.resize(mesh.num_tets());
  tbb::parallel_for(
      tbb::blocked_range<int>(0, mesh.num_tets(), 256), [&](const tbb::blocked_range<int>& r) {
        element_states_range(mesh, x, v, frames, r.begin(), r.end(), states);
      });
}

/// A stiffness scale, if any, has one entry per tet (its values fem::ElasticForce checks).
void check_stiffness_scale(const fem::MaterialModel& nominal, Eigen::Index tets) {
  if (nominal.stiffness_scale && Eigen::Index(nominal.stiffness_scale->size()) != tets)
    element_state_error("nominal.stiffness_scale",
        to_text(nominal.stiffness_scale->size()) + " entries for " + to_text(tets) + " tets");
}

} // namespace

ReconstructionMesh::ReconstructionMesh(const mesh::TetMesh& mesh, fem::MaterialModel nominal_model)
    : rest(fem::precompute_rest_data(mesh))
    , tets(mesh.tets())
    , num_vertices(mesh.num_vertices())
    , nominal(std::move(nominal_model)) {
  check_stiffness_scale(nominal, tets.rows());
}

ReconstructionMesh::ReconstructionMesh(std::vector<fem::TetRestData> rest_data, Tets tet_indices,
    int n, fem::MaterialModel nominal_model)
    : rest(std::move(rest_data))
    , tets(std::move(tet_indices))
    , num_vertices(n)
    , nominal(std::move(nominal_model)) {
  if (rest.size() != static_cast<size_t>(tets.rows()))
    element_state_error(
        "mesh", to_text(rest.size()) + " rest data for " + to_text(tets.rows()) + " tets");
  if (tets.size() > 0 && (tets.minCoeff() < 0 || tets.maxCoeff() >= n))
    element_state_error("mesh", "a tet index is outside [0, " + to_text(n) + ")");
  check_stiffness_scale(nominal, tets.rows());
}

void compute_element_states(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    std::vector<ElementState>& states) {
  element_states(mesh, x, v, nullptr, states);
}

void compute_element_states(const ReconstructionMesh& mesh, const VecX& x, const VecX& v,
    const fem::ElasticForce& frames, std::vector<ElementState>& states) {
  ELASTOLEARN_CHECK(frames.tets().rows() == mesh.tets.rows() && frames.caches_positions(x),
      "the element force's cached frames are not those of this mesh at these positions");
  element_states(mesh, x, v, &frames, states);
}

void StretchSampleOptions::validate() const {
  if (frame_stride < 1)
    throw InputError("stretch_samples.frame_stride", "must be ≥ 1, got " + to_text(frame_stride));
  if (max_samples < 0)
    throw InputError("stretch_samples.max_samples", "must be ≥ 0, got " + to_text(max_samples));
}

MatX collect_stretches(const ReconstructionMesh& mesh, const std::vector<VecX>& positions,
    const StretchSampleOptions& options) {
  options.validate();
  detail::check_frames(mesh, nullptr, positions, nullptr, nullptr);
  const std::vector<int> frames
      = detail::selected_frames(int(positions.size()), options.frame_stride);
  const Eigen::Index m = mesh.num_tets();
  const Eigen::Index total = Eigen::Index(frames.size()) * m;
  const Eigen::Index step = options.max_samples > 0
      ? std::max<Eigen::Index>(1, (total + options.max_samples - 1) / options.max_samples)
      : 1;
  const Eigen::Index rows = (total + step - 1) / step;
  MatX out(rows, 3);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, rows, 1024),
      [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index i = r.begin(); i < r.end(); ++i) {
          const Eigen::Index sample = i * step;
          const int e = int(sample % m);
          const VecX& x = positions[frames[sample / m]];
          const Mat3 F = fem::deformation_gradient(
              fem::gather_tet(x, mesh.tets.row(e).transpose()), mesh.rest[e]);
          out.row(i) = material::principal_frame(F).stretches.transpose();
        }
      });
  return out;
}

namespace detail {

void check_frames(const ReconstructionMesh& mesh, const fem::DofMap* dofs,
    const std::vector<VecX>& positions, const std::vector<VecX>* velocities,
    const std::vector<VecX>* target_forces) {
  const Eigen::Index n3 = 3 * Eigen::Index(mesh.num_vertices);
  if (positions.empty())
    element_state_error("positions", "no frames");
  if (dofs != nullptr && dofs->num_dofs() != n3)
    element_state_error(
        "dofs", "the DofMap has " + to_text(dofs->num_dofs()) + " dofs, the mesh " + to_text(n3));
  const std::array<std::pair<const char*, const std::vector<VecX>*>, 3> lists {
    { { "positions", &positions }, { "velocities", velocities },
        { "target_forces", target_forces } }
  };
  for (const auto& [name, list] : lists) {
    if (list == nullptr)
      continue;
    if (list->size() != positions.size())
      element_state_error(
          name, to_text(list->size()) + " frames but " + to_text(positions.size()) + " positions");
    for (size_t t = 0; t < list->size(); ++t) {
      const VecX& f = (*list)[t];
      if (f.size() != n3)
        element_state_error(std::string(name) + "[" + to_text(t) + "]",
            "length " + to_text(f.size()) + ", expected 3n = " + to_text(n3));
      if (!f.allFinite())
        element_state_error(
            std::string(name) + "[" + to_text(t) + "]", "contains a non-finite value");
    }
  }
}

std::vector<int> selected_frames(int count, int stride) {
  std::vector<int> frames;
  for (int t = 0; t < count; t += stride)
    frames.push_back(t);
  return frames;
}

} // namespace detail

} // namespace elastolearn::learn
