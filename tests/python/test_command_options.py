"""The command line's options of observe, learn and evaluate, from Python: the same names
(underscores), the same results as the command with the same values, the same errors."""

import json
import shutil
import sys

import numpy as np
import pytest

import elastolearn as el
from conftest import SMALL_SCENE, TRUE_YOUNG


# A short learning run (0.3 s): the loop runs iterations 0 to 3, so the checkpoint written after
# iteration 1 is in the middle of the run.
LEARN_OPTIONS = dict(noise=0.0, max_iterations=3, patience=3, kernels=5, modes=5, forward_fit=0,
                     parameter_fit_iterations=10, network_samples=2000)


def cli_flags(options):
    """The command-line flags of Python keyword options (True: a bare flag)."""
    flags = []
    for name, v in options.items():
        flag = "--" + name.replace("_", "-")
        if v is True:
            flags.append(flag)
        elif v is not False:
            flags += [flag, v]
    return flags


@pytest.fixture
def learning_case(tmp_path):
    """(scene, observations) where learning finds a correction: the small bar sagging under 3 g
    for 40 steps, observed from a neo-Hookean truth that the corotated nominal's parameters
    cannot fit (the recipe chooses a loop iteration, or its network)."""
    scene = tmp_path / "sag.json"
    scene.write_text(json.dumps(dict(SMALL_SCENE, gravity=[0, -30, 0],
                                     time={"dt": 0.002, "frames": 40})))
    material = el.Material.from_json({"format": "elastolearn-material/1", "correction": None,
                                      "material": dict(SMALL_SCENE["material"],
                                                       model="neohookean", young=TRUE_YOUNG)})
    sim = el.simulate(scene, material=material)
    el.observe(sim.trajectory, visible_fraction=0.5, output=tmp_path / "sag_obs.h5")
    return scene, tmp_path / "sag_obs.h5"


def test_dropout_equals_the_cli(truth, cli, tmp_path):
    # 21 frames × 8 vertices with bursts of mean 3 frames; seed 3 loses some entries of several
    # vertices and keeps most.
    r = cli("observe", truth, "--visible-fraction", 0.5, "--noise", 1e-4, "--dropout", 0.3,
            "--dropout-burst", 3, "--seed", 3, "-o", tmp_path / "cli.h5")
    assert r.returncode == 0, r.stdout + r.stderr
    from_cli = el.read_observations(tmp_path / "cli.h5")
    obs = el.observe(truth, visible_fraction=0.5, noise=1e-4, dropout=0.3, dropout_burst=3,
                     seed=3, output=tmp_path / "py.h5")
    assert obs.valid.dtype == bool and obs.valid.shape == (21, obs.num_observed)
    assert np.array_equal(obs.valid, from_cli.valid)
    assert np.array_equal(obs.positions, from_cli.positions, equal_nan=True)
    assert obs.metadata == from_cli.metadata
    assert obs.metadata["dropout"] == "0.3" and obs.metadata["dropout_burst"] == "3"
    # The file written from Python holds the same mask.
    assert np.array_equal(el.read_observations(tmp_path / "py.h5").valid, obs.valid)

    lost = ~obs.valid
    assert 0 < lost.sum() < lost.size // 2
    assert obs.num_valid == obs.valid.sum()
    # Lost entries are NaN; seen ones are the observation without dropout (the dropout draws
    # from its own stream: the vertex choice and the noise do not change).
    assert np.isnan(obs.positions[lost]).all()
    clean = el.observe(truth, visible_fraction=0.5, noise=1e-4, seed=3)
    assert clean.valid.all()
    assert np.array_equal(obs.positions[obs.valid], clean.positions[obs.valid])


@pytest.mark.parametrize("flag,value", [("dropout", 1.0), ("dropout", -0.1),
                                        ("dropout_burst", 0.5)])
def test_bad_dropout_raises_the_cli_message(truth, cli, tmp_path, flag, value):
    r = cli("observe", truth, "--visible-fraction", 0.5, "--" + flag.replace("_", "-"), value,
            *(["--dropout", 0.2] if flag == "dropout_burst" else []), "-o", tmp_path / "o.h5")
    assert r.returncode != 0
    extra = {"dropout": 0.2} if flag == "dropout_burst" else {}
    with pytest.raises(el.InputError) as error:
        el.observe(truth, visible_fraction=0.5, **{flag: value}, **extra)
    # The one line the command prints is "elastolearn: error: <the message>".
    assert r.stderr.strip() == f"elastolearn: error: {error.value}"
    assert str(value) in str(error.value) or f"{value:g}" in str(error.value)
    assert not (tmp_path / "o.h5").exists()


def test_vertex_list_file_equals_the_cli(truth, cli, tmp_path):
    (tmp_path / "ids.txt").write_text("# three vertices\n3, 0\n17\n")
    r = cli("observe", truth, "--vertices", tmp_path / "ids.txt", "-o", tmp_path / "cli.h5")
    assert r.returncode == 0, r.stdout + r.stderr
    obs = el.observe(truth, vertices=tmp_path / "ids.txt")
    from_cli = el.read_observations(tmp_path / "cli.h5")
    assert np.array_equal(obs.vertex_ids, [3, 0, 17])
    assert np.array_equal(obs.positions, from_cli.positions)
    assert obs.metadata == from_cli.metadata
    with pytest.raises(el.InputError, match="ids.txt"):
        el.observe(truth, vertices=tmp_path / "ids.txt", output=tmp_path / "ids.txt")


def test_observation_validity_mask_round_trip(tmp_path):
    positions = np.zeros((4, 2, 3))
    valid = np.array([[1, 1], [0, 1], [1, 0], [1, 1]], dtype=bool)
    positions[~valid] = np.nan
    obs = el.Observation([5, 9], positions, dt=0.01, valid=valid)
    assert np.array_equal(obs.valid, valid) and obs.num_valid == 6
    obs.write(tmp_path / "o.h5")
    back = el.read_observations(tmp_path / "o.h5")
    assert np.array_equal(back.valid, valid)
    assert np.array_equal(back.positions, positions, equal_nan=True)
    assert el.Observation([5, 9], np.zeros((4, 2, 3)), dt=0.01).valid.all()
    with pytest.raises(el.InputError, match=r"valid: expected an array of shape \(4, 2\)"):
        el.Observation([5, 9], positions, dt=0.01, valid=valid.T)
    # A NaN where the marker is said to be seen is refused, as in a file.
    with pytest.raises(el.InputError, match="positions"):
        el.Observation([5, 9], positions, dt=0.01)


def same_learning(resumed, whole):
    """A resumed run's result is the uninterrupted run's: the same material and loop history,
    bit for bit. It validates the candidates it still knows (the loop's best, the iterations
    after the resume; docs/learning_recipe.md, "Resuming"), each with the same error."""
    assert resumed.to_json()["correction"] == whole.to_json()["correction"]

    def history(m):
        return [{k: v for k, v in r.items() if k != "seconds"} for r in m.training["history"]]

    assert history(resumed) == history(whole)
    r, w = resumed.training["recipe"], whole.training["recipe"]
    assert r["parameter_fit"]["fitted"] == w["parameter_fit"]["fitted"]

    def key(c):
        return c["kind"], c["iteration"], c["validation_rms_error_m"]

    assert {key(c) for c in r["candidates"]} <= {key(c) for c in w["candidates"]}
    assert key(r["candidates"][r["chosen"]]) == key(w["candidates"][w["chosen"]])


class Recorder:
    """A stdout for learn(verbose=True): keeps the lines printed and, when iteration 2's line is
    printed, copies the checkpoint (then of iterations 0 and 1): the state a run interrupted
    there resumes from."""

    def __init__(self, checkpoint=None, copy=None):
        self.checkpoint, self.copy, self.lines = checkpoint, copy, []

    def write(self, text):
        self.lines += text.splitlines()
        if self.copy and text.startswith("iteration 2") and not self.copy.exists():
            shutil.copy(self.checkpoint, self.copy)
        return len(text)

    def flush(self):
        pass

    def iterations(self):
        return [int(line.split()[1].rstrip(":")) for line in self.lines
                if line.startswith("iteration ")]


def test_resume_from_a_checkpoint_gives_the_uninterrupted_result(learning_case, tmp_path,
                                                                 monkeypatch):
    scene, observations = learning_case
    checkpoint = tmp_path / "learned.json.checkpoint.json"  # the default beside the output
    middle = tmp_path / "middle.json"
    whole_run = Recorder(checkpoint, middle)
    monkeypatch.setattr(sys, "stdout", whole_run)
    whole = el.learn(scene, observations, output=tmp_path / "learned.json", verbose=True,
                     **LEARN_OPTIONS)
    assert whole_run.iterations() == [0, 1, 2, 3]
    # A loop iteration's RBF, or the network distilled from it (stage 5).
    assert whole.correction is not None
    assert whole.training["recipe"]["chosen_kind"] in ("loop", "network")
    state = json.loads(middle.read_text())["state"]
    assert state["next_iteration"] == 2 and not state["finished"]

    resumed_run = Recorder()
    monkeypatch.setattr(sys, "stdout", resumed_run)
    resumed = el.learn(scene, observations, checkpoint=middle, resume=True, verbose=True,
                       **LEARN_OPTIONS)
    monkeypatch.undo()
    # It went on from the checkpoint (no parameter fit, iterations 2 and 3 only) to the same
    # result, and rewrote the checkpoint.
    assert resumed_run.lines[0] == f"resuming from {middle} at iteration 2"
    assert resumed_run.iterations() == [2, 3]
    assert not any(line.startswith("parameter fit") for line in resumed_run.lines)
    same_learning(resumed, whole)
    assert json.loads(middle.read_text())["state"]["next_iteration"] == 4

    with pytest.raises(el.InputError, match="other learning options"):
        el.learn(scene, observations, checkpoint=middle, resume=True,
                 **dict(LEARN_OPTIONS, kernels=6))
    with pytest.raises(el.InputError, match=r"none.json: no checkpoint to resume from"):
        el.learn(scene, observations, checkpoint=tmp_path / "none.json", resume=True,
                 **LEARN_OPTIONS)
    with pytest.raises(el.InputError, match="resume: needs a checkpoint"):
        el.learn(scene, observations, resume=True, **LEARN_OPTIONS)
    with pytest.raises(el.InputError, match="sag_obs.h5"):
        el.learn(scene, observations, checkpoint=observations, **LEARN_OPTIONS)


def test_learn_flags_set_what_the_cli_sets(learning_case, cli, tmp_path):
    # Every flag away from its default: a checkpoint records the options and refuses a resume
    # with others, so resuming the command's checkpoint from Python checks that each keyword
    # sets what its flag sets; the result is the command's.
    scene, observations = learning_case
    flags = dict(LEARN_OPTIONS, max_iterations=1, no_parameter_fit=True, pod_forward_only=True,
                 unprojected_reconstruction=True, full_space_weight=0.2, no_damping=True,
                 linear_tail=True, stress_kernels=True, no_neo_hookean_tail=True,
                 no_mass_damping=True,
                 allow_rest_stress=True, validation_fraction=0.25, frame_stride=2,
                 smoothness=0.05, no_backtrack=True, no_stability_cuts=True,
                 forward_fit_tolerance=0.05)
    r = cli("learn", scene, "--observations", observations, "-o", tmp_path / "cli.json", "-q",
            *cli_flags(flags))
    assert r.returncode == 0, r.stdout + r.stderr
    from_cli = el.load_material(tmp_path / "cli.json")
    options = from_cli.training["options"]
    assert not options["fit_parameters"] and not options["loop"]["rbf"]["fit_damping"]

    resumed = el.learn(scene, observations, resume=True,
                       checkpoint=tmp_path / "cli.json.checkpoint.json", **flags)
    assert resumed.training["options"] == options
    same_learning(resumed, from_cli)
    assert set(flags) <= set(el.learn_options())
    # One flag more: refused.
    with pytest.raises(el.InputError, match="other learning options"):
        el.learn(scene, observations, resume=True,
                 checkpoint=tmp_path / "cli.json.checkpoint.json",
                 **dict(flags, damping_quadratic_tail=True))


def test_evaluate_options(small_scene, truth, cli, tmp_path):
    nominal = tmp_path / "nominal.json"
    nominal.write_text(json.dumps({"format": "elastolearn-material/1", "correction": None,
                                   "material": SMALL_SCENE["material"]}))
    true_material = el.Material.from_json({"format": "elastolearn-material/1",
                                           "correction": None,
                                           "material": dict(SMALL_SCENE["material"],
                                                            young=TRUE_YOUNG)})
    true_material.write(tmp_path / "true.json")
    r = cli("evaluate", small_scene, "--material", tmp_path / "true.json", "--truth", truth,
            "--solver", "cg", "--json", tmp_path / "cli.json", "-q")
    assert r.returncode == 0, r.stdout + r.stderr
    report = el.evaluate(small_scene, tmp_path / "true.json", truth, solver="cg",
                         json=tmp_path / "py.json")
    assert json.loads((tmp_path / "py.json").read_text()) == report
    from_cli = json.loads((tmp_path / "cli.json").read_text())
    for model in ("nominal", "learned"):
        assert report[model]["err_L_percent"] == from_cli[model]["err_L_percent"]
    # The true material with the scene's solver (cholmod) repeats the truth's run exactly; with
    # cg it differs by the iterative solver's tolerance: the solver option took effect.
    exact = el.evaluate(small_scene, tmp_path / "true.json", truth)
    assert exact["learned"]["err_L_percent"] == 0
    assert 0 < report["learned"]["err_L_percent"] < 1e-3 * report["nominal"]["err_L_percent"]

    with pytest.raises(el.InputError, match="truth_material: is used by the report only"):
        el.evaluate(small_scene, nominal, truth, truth_material=true_material)
    with pytest.raises(el.InputError, match="cholmod"):
        el.evaluate(small_scene, nominal, truth, solver="qr")
    with pytest.raises(el.InputError, match="truth.h5"):
        el.evaluate(small_scene, nominal, truth, json=truth)

    el.evaluate(small_scene, nominal, truth, report=tmp_path / "report",
                truth_material=true_material)
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    assert summary["command"] == "evaluate"
    assert summary["nominal"]["err_L_percent"] == pytest.approx(
        report["nominal"]["err_L_percent"], rel=1e-6)
    assert (tmp_path / "report" / "report.html").stat().st_size > 0


def test_learn_report_and_network_options(learning_case, tmp_path):
    scene, observations = learning_case
    true_material = el.Material.from_json({"format": "elastolearn-material/1",
                                           "correction": None,
                                           "material": dict(SMALL_SCENE["material"],
                                                            model="neohookean",
                                                            young=TRUE_YOUNG)})
    with pytest.raises(el.InputError, match="truth_material: is used by the report only"):
        el.learn(scene, observations, truth_material=true_material, **LEARN_OPTIONS)
    with pytest.raises(el.InputError, match="network_kind: must be auto, energy or stress"):
        el.learn(scene, observations, network_kind="big", **LEARN_OPTIONS)

    # The recipe chooses a correction here, so stage 5 distils it (a stress network on request)
    # and validates the network as the last candidate.
    learned = el.learn(scene, observations, report=tmp_path / "report",
                       truth_material=true_material, network_kind="stress", **LEARN_OPTIONS)
    candidates = learned.training["recipe"]["candidates"]
    assert candidates[-1]["kind"] == "network"
    assert learned.training["network"]["kind"] == "stress"
    chosen = candidates[learned.training["recipe"]["chosen"]]
    assert learned.training["network"]["chosen"] == (chosen["kind"] == "network")
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    assert summary["command"] == "learn"
    assert summary["recipe"] == learned.training["recipe"]
    data = json.loads((tmp_path / "report" / "report_data.json").read_text())
    assert data["correction"]["has_truth"]
    assert (tmp_path / "report" / "report.html").stat().st_size > 0

    kept = el.learn(scene, observations, no_network=True, **LEARN_OPTIONS)
    assert "network" not in kept.training
    assert all(c["kind"] != "network" for c in kept.training["recipe"]["candidates"])
