#include <elastolearn/core/error.hpp>
#include <elastolearn/fem/mass.hpp>

namespace elastolearn::fem {

const char* to_string(MassType type) {
  return type == MassType::Lumped ? "lumped" : "consistent";
}

MassType mass_type_from_string(const std::string& name) {
  if (name == "lumped")
    return MassType::Lumped;
  if (name == "consistent")
    return MassType::Consistent;
  throw InputError("mass", "unknown mass type '" + name + "' (valid: lumped, consistent)");
}

VecX lumped_vertex_masses(
    const Tets& tets, const std::vector<TetRestData>& rest, int num_vertices, double density) {
  VecX m = VecX::Zero(num_vertices);
  for (Eigen::Index e = 0; e < tets.rows(); ++e)
    for (int a = 0; a < 4; ++a)
      m[tets(e, a)] += density * rest[e].volume / 4.0;
  return m;
}

VecX lumped_dof_masses(const VecX& vertex_masses) {
  VecX out(3 * vertex_masses.size());
  for (Eigen::Index v = 0; v < vertex_masses.size(); ++v)
    out.segment<3>(3 * v).setConstant(vertex_masses[v]);
  return out;
}

Mat12 consistent_mass_block(double volume, double density) {
  Mat12 block;
  const double base = density * volume / 20.0;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      block.block<3, 3>(3 * a, 3 * b) = (a == b ? 2.0 : 1.0) * base * Mat3::Identity();
  return block;
}

std::vector<double> consistent_mass_blocks(const std::vector<TetRestData>& rest, double density) {
  std::vector<double> blocks(rest.size() * 144, 0.0);
  for (size_t e = 0; e < rest.size(); ++e)
    Eigen::Map<Mat12>(blocks.data() + 144 * e) = consistent_mass_block(rest[e].volume, density);
  return blocks;
}

} // namespace elastolearn::fem
