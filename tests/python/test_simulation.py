"""Scenes, simulation and trajectory files from Python, against the command line."""

import json

import numpy as np
import pytest

import elastolearn as el


def test_python_simulation_equals_the_cli_trajectory_bit_for_bit(small_scene, cli, tmp_path):
    # Same library function, same inputs: the same doubles, not just close ones.
    out = tmp_path / "cli.h5"
    r = cli("simulate", small_scene, "-o", out, "-q")
    assert r.returncode == 0, r.stdout + r.stderr
    from_cli = el.read_trajectory(out)

    sim = el.simulate(small_scene)
    assert sim.completed and sim.message == ""
    n = el.load_scene(small_scene).num_vertices
    assert sim.positions.shape == (21, n, 3) and sim.positions.dtype == np.float64
    assert np.array_equal(sim.positions, from_cli.positions)
    assert np.array_equal(sim.velocities, from_cli.velocities)
    assert np.array_equal(sim.time, from_cli.time)
    assert np.array_equal(sim.trajectory.tets, from_cli.tets)
    assert sim.trajectory.metadata == from_cli.metadata
    # It sags under gravity, and the fixed end stays put.
    assert sim.positions[-1, :, 1].min() < -1e-4
    fixed = np.flatnonzero(sim.trajectory.rest_positions[:, 0] == 0)
    assert len(fixed) == 4
    assert np.array_equal(sim.positions[:, fixed], np.broadcast_to(
        sim.trajectory.rest_positions[fixed], (21, 4, 3)))

    # Written from Python, the file is the command line's too.
    written = el.simulate(el.load_scene(small_scene), output=tmp_path / "py.h5")
    assert np.array_equal(written.positions, from_cli.positions)
    assert np.array_equal(el.read_trajectory(tmp_path / "py.h5").positions, from_cli.positions)


def test_simulate_options_frames_every_and_material(small_scene, tmp_path):
    full = el.simulate(small_scene)
    short = el.simulate(small_scene, frames=10, every=5)
    assert short.positions.shape[0] == 3  # states 0, 5, 10
    assert np.array_equal(short.positions, full.positions[[0, 5, 10]])
    assert np.allclose(short.time, [0, 0.01, 0.02], rtol=0, atol=1e-15)

    # A twice stiffer material (as --material) sags less.
    stiff = el.Material.from_json({"format": "elastolearn-material/1", "correction": None,
                                   "material": {"model": "corotated", "young": 2e5,
                                                "poisson": 0.3, "density": 1000,
                                                "damping": {"alpha0": 0.1, "alpha1": 0.001}}})
    stiffer = el.simulate(small_scene, material=stiff)
    assert 0 < -stiffer.positions[-1, :, 1].min() < -full.positions[-1, :, 1].min()


def test_scene_properties(small_scene):
    scene = el.Scene.load(small_scene)
    # A 4 × 1 × 1 box grid: 5 · 2 · 2 vertices.
    assert scene.num_vertices == 20
    assert scene.rest_positions.shape == (20, 3)
    assert scene.tets.shape == (scene.num_tets, 4) and scene.tets.dtype == np.int32
    assert scene.tets.min() == 0 and scene.tets.max() == 19
    assert scene.dt == 0.002 and scene.frames == 20
    assert scene.size == pytest.approx(np.linalg.norm([0.2, 0.05, 0.05]), rel=1e-12)
    assert scene.material.elastic_model == "corotated"
    scene.frames = 5
    assert el.simulate(scene).positions.shape[0] == 6
    with pytest.raises(el.InputError, match="frames"):
        scene.frames = 0


def test_scene_from_json_gives_the_file_s_simulation(small_scene):
    from conftest import SMALL_SCENE
    a = el.simulate(el.Scene.from_json(SMALL_SCENE, name="inline.json"))
    b = el.simulate(small_scene)
    assert np.array_equal(a.positions, b.positions)


def test_trajectory_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    rest = rng.random((4, 3))
    positions = rest + 1e-3 * rng.standard_normal((3, 4, 3))
    velocities = rng.standard_normal((3, 4, 3))
    tets = np.array([[0, 1, 2, 3]], dtype=np.int32)
    traj = el.Trajectory(rest, positions, [0.0, 0.1, 0.2], tets=tets, velocities=velocities,
                         metadata={"note": "from python"})
    el.write_trajectory(tmp_path / "t.h5", traj)
    back = el.read_trajectory(tmp_path / "t.h5")
    assert np.array_equal(back.rest_positions, rest)
    assert np.array_equal(back.positions, positions)
    assert np.array_equal(back.velocities, velocities)
    assert np.array_equal(back.time, [0.0, 0.1, 0.2])
    assert np.array_equal(back.tets, tets)
    assert back.metadata["note"] == "from python"
    assert back.num_frames == 3 and back.num_vertices == 4


def test_errors_name_the_file_and_field(small_scene, tmp_path):
    bad = json.loads(small_scene.read_text())
    bad["material"]["young"] = -3
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(el.InputError) as e:
        el.simulate(path)
    assert "bad.json" in str(e.value) and "material.young" in str(e.value)
    assert isinstance(e.value, ValueError)

    with pytest.raises(el.InputError, match="missing.h5"):
        el.read_trajectory(tmp_path / "missing.h5")
    # A wrong array shape names the argument.
    with pytest.raises(el.InputError, match=r"positions: expected an array of shape \(T, n, 3\)"):
        el.Trajectory(np.zeros((4, 3)), np.zeros((3, 4)), [0.0, 0.1, 0.2])
    # An invalid trajectory is refused when written, naming the file; nothing is left behind.
    with pytest.raises(el.InputError, match="t.h5"):
        el.Trajectory(np.zeros((4, 3)), np.full((1, 4, 3), np.nan), [0.0]).write(tmp_path / "t.h5")
    assert not (tmp_path / "t.h5").exists()
    # An output that is an input is refused before anything runs.
    with pytest.raises(el.InputError, match="bar.json"):
        el.simulate(small_scene, output=small_scene)


def test_a_diverging_simulation_keeps_its_frames_and_warns(tmp_path):
    # One Newton iteration per attempt to 1e-12, no substeps, cannot converge once the bar moves
    # (the CLI test's case).
    from conftest import SMALL_SCENE
    scene = el.Scene.from_json(dict(SMALL_SCENE, solver={"max_newton_iterations": 1,
                                                         "newton_tolerance": 1e-12,
                                                         "max_step_halvings": 0}))
    with pytest.warns(RuntimeWarning, match="diverged at frame"):
        sim = el.simulate(scene)
    assert not sim.completed and "diverged at frame" in sim.message
    assert 1 <= sim.positions.shape[0] < 21
    assert sim.trajectory.metadata["status"].startswith("stopped: ")


def test_arguments_of_the_wrong_kind_raise_type_errors(small_scene):
    with pytest.raises(TypeError, match="scene: expected an elastolearn.Scene"):
        el.simulate(42)
    with pytest.raises(TypeError, match="material: expected an elastolearn.Material"):
        el.simulate(small_scene, material=3.5)
