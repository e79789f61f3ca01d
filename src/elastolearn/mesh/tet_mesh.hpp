#pragma once
/// \file The rest-state tetrahedral mesh: rest positions, tets, and derived surface data.
#include <elastolearn/core/types.hpp>

#include <string>
#include <vector>

namespace elastolearn::mesh {

/// Element quality summary (rest shape).
struct MeshQuality {
  double min_volume = 0; ///< smallest tet volume [m³]
  double max_volume = 0; ///< largest tet volume [m³]
  double min_dihedral_deg = 0; ///< smallest dihedral angle over all tets [degrees]
  double max_dihedral_deg = 0; ///< largest dihedral angle over all tets [degrees]
  double max_radius_ratio = 0; ///< max circumradius / (3·inradius) (1 = regular tet)
  int num_degenerate = 0; ///< tets with |6V| below 1e-12 · (longest edge)³
};

/// A linear tetrahedral mesh in its rest configuration.
///
/// Invariants, checked on construction (throws InputError naming `source`): at least one tet,
/// all coordinates finite, all indices in range, every tet positively oriented
/// (det[x1-x0, x2-x0, x3-x0] > 0) and not degenerate. Vertices referenced by no tet are allowed.
/// Surface faces are the tet faces that belong to exactly one tet, oriented outward
/// (counter-clockwise seen from outside).
class TetMesh {
  public:
  TetMesh() = default;
  /// \param rest  n×3 rest positions [m]
  /// \param tets  m×4 vertex indices
  /// \param source  file name or description used in error messages
  TetMesh(Positions rest, Tets tets, const std::string& source = "mesh");

  int num_vertices() const { return static_cast<int>(m_rest.rows()); }
  int num_tets() const { return static_cast<int>(m_tets.rows()); }
  const Positions& rest_positions() const { return m_rest; }
  const Tets& tets() const { return m_tets; }

  /// Boundary triangles, outward oriented (f×3).
  const Faces& surface_faces() const { return m_surface_faces; }
  /// Sorted indices of the vertices on the boundary.
  const std::vector<int>& surface_vertices() const { return m_surface_vertices; }

  /// Axis-aligned bounding box of the rest positions.
  Box3 bounding_box() const;
  /// Length of the rest bounding-box diagonal [m] (the paper's "object size" for err_L).
  double bounding_box_diagonal() const { return bounding_box().diagonal().norm(); }
  /// Rest volume of every tet [m³] (length m, all positive).
  VecX element_volumes() const;
  /// Sum of element volumes [m³].
  double total_volume() const { return element_volumes().sum(); }
  /// Quality statistics of the rest tets.
  MeshQuality quality() const;

  private:
  Positions m_rest;
  Tets m_tets;
  Faces m_surface_faces;
  std::vector<int> m_surface_vertices;
};

/// Signed volume of a tet: det[b-a, c-a, d-a] / 6 (positive when positively oriented).
double signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

} // namespace elastolearn::mesh
