#pragma once
/// \file Heterogeneous materials in scene files: the "regions" of an inline scene material
/// (docs/scene_format.md, "Heterogeneous materials"),
///   "regions": [{"select": E, "young": Pa}, ...]
/// give the elements that an element selection E picks (by their rest centroid) another Young's
/// modulus, with the material's Poisson ratio, model and damping. Every model's stress is linear
/// in (μ, λ), so a region is the per-element stiffness scale young / material.young
/// (fem::MaterialModel::stiffness_scale).
#include <elastolearn/io/json_fields.hpp>
#include <elastolearn/mesh/tet_mesh.hpp>

#include <memory>
#include <vector>

namespace elastolearn::io {

/// The tets an element selection object picks by rest centroid c (possibly none):
///   {"elements": [i, ...]}                                 tet ids
///   {"box": {"min": [..], "max": [..]}}                      c in the closed box
///   {"plane": {"axis": "x", "value": v, "tolerance": t}}     |c_axis − v| ≤ t (t ≥ 0 required)
///   {"layers": {"axis": "x", "period": p, "start": a, "thickness": w}}
///                                          (c_axis − a) mod p in [0, w): every p-th slab, w thick
/// Sorted ascending. Throws InputError naming the field for a malformed object.
std::vector<int> select_elements(const JsonObject& selection, const mesh::TetMesh& mesh);

/// The per-tet stiffness scale of `material`'s "regions" (an inline scene material object with
/// a positive "young"), later regions overriding earlier ones where they overlap; 1 outside every
/// region. Throws InputError naming the field ("scene.json: material.regions[1].select: selects
/// no element", "...regions[0].young: expected a positive number, got -3", an empty or
/// non-array "regions", unknown keys).
std::shared_ptr<const std::vector<double>> parse_material_regions(
    const JsonObject& material, const mesh::TetMesh& mesh);

} // namespace elastolearn::io
