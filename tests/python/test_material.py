"""A material's principal stress at given stretches, against analytic values and finite
differences of its energy; material files round trip."""

import numpy as np
import pytest

import elastolearn as el

E, NU = 1e5, 0.3
MU = E / (2 * (1 + NU))
LAMBDA = E * NU / ((1 + NU) * (1 - 2 * NU))


def material(model):
    return el.Material.from_json({"format": "elastolearn-material/1", "correction": None,
                                  "material": {"model": model, "young": E, "poisson": NU,
                                               "density": 1000}})


STRETCHES = np.array([[1.0, 1.0, 1.0], [1.1, 0.95, 0.9], [1.3, 1.2, 0.7], [0.8, 0.8, 0.8],
                      [1.02, 1.0, 0.99]])


@pytest.mark.parametrize("model", ["corotated", "stvk", "neohookean"])
def test_stress_is_zero_at_rest_and_the_energy_s_gradient(model):
    m = material(model)
    stress = m.principal_stress(STRETCHES)
    assert stress.shape == STRETCHES.shape and stress.dtype == np.float64
    # Rest: no stress (to round-off of a 1e5 Pa modulus).
    assert np.abs(stress[0]).max() < 1e-9 * E
    # P̂ = ∂Ψ/∂σ: central differences, error O(h²) ~ E·h² = 1e-7 Pa, round-off ~ Ψ·ε/h ~ 1e-5 Pa.
    h = 1e-6
    for k in range(3):
        step = np.zeros(3)
        step[k] = h
        fd = (m.energy(STRETCHES + step) - m.energy(STRETCHES - step)) / (2 * h)
        assert np.allclose(stress[:, k], fd, rtol=1e-7, atol=1e-4)


def test_corotated_stress_is_the_analytic_formula():
    # P̂ = 2μ(σ − 1) + λ tr(σ − 1) (DESIGN.md, the nominal model).
    expected = 2 * MU * (STRETCHES - 1) + LAMBDA * (STRETCHES - 1).sum(axis=1, keepdims=True)
    assert np.allclose(material("corotated").principal_stress(STRETCHES), expected,
                       rtol=1e-13, atol=1e-9)


def test_rows_in_any_order_give_the_same_stresses_permuted():
    m = material("neohookean")
    s = np.array([[0.9, 1.2, 1.05]])
    p = m.principal_stress(s)
    order = [1, 2, 0]
    assert np.array_equal(m.principal_stress(s[:, order]), p[:, order])


def test_shape_errors_name_the_argument():
    with pytest.raises(el.InputError, match=r"stretches: expected an array of shape \(n, 3\)"):
        material("corotated").principal_stress(np.ones((2, 2)))
    with pytest.raises(el.InputError, match="stretch_rates"):
        material("corotated").principal_stress(np.ones((2, 3)), np.ones((3, 3)))


def test_material_file_round_trip(tmp_path):
    m = material("stvk")
    m.write(tmp_path / "m.json")
    back = el.load_material(tmp_path / "m.json")
    assert back.to_json() == m.to_json()
    assert back.nominal["young"] == E and back.correction is None
    assert np.array_equal(back.principal_stress(STRETCHES), m.principal_stress(STRETCHES))
    (tmp_path / "bad.json").write_text('{"format": "elastolearn-material/1", "material": '
                                       '{"model": "corotated", "young": 1e5, "poisson": 0.7}}')
    with pytest.raises(el.InputError, match="bad.json: material.poisson"):
        el.load_material(tmp_path / "bad.json")
