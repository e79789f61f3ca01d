#!/usr/bin/env python3
"""Learning a material from Python, end to end (the course's 04_learning, as a script).

Run from the repository root after building (docs/python.md):

    PYTHONPATH=build/python /usr/bin/python3 examples/07_python/learn_bar.py [--quick] [--out DIR]
        [--dropout P]

1. load the training and test scenes of examples/04_learning (nominal: corotated, E = 1.75 MPa);
2. simulate the "real" object (truth.json: neo-Hookean, E = 1 MPa) on both motions;
3. observe 13 % of the training motion's surface vertices, with 0.1 mm of noise (and, with
   --dropout P, a fraction P of the markers lost in occlusion bursts);
4. learn a material from them with the one recipe (docs/learning_recipe.md);
5. evaluate nominal and learned material on the test motion (err_L, paper 000 Table 1), with a
   report (DIR/report/report.html: plots and an animation; docs/report.md);
6. compare the stresses of the three materials along a uniaxial stretch within the training
   motion's stretches.

--quick runs a shorter recipe (1 loop iteration, no forward fit) for a smoke test.
"""

import argparse
import pathlib
import time

import numpy as np

import elastolearn as el

HERE = pathlib.Path(__file__).resolve().parent
DATA = HERE.parent / "04_learning"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a shorter recipe (smoke test)")
    parser.add_argument("--out", default="elastolearn-python", help="output folder")
    parser.add_argument("--dropout", type=float, default=0.0,
                        help="fraction of lost marker-frames, as observe --dropout (default 0)")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    # 1. Scenes and the true material.
    train = el.load_scene(DATA / "bar_train.json")
    test = el.load_scene(DATA / "bar_test.json")
    truth = el.load_material(DATA / "truth.json")
    print(f"training scene: {train}; nominal {train.material.description}")
    print(f"true material:  {truth.description}")

    # 2. The "real" motions (HDF5 files, as `elastolearn simulate --material truth.json`).
    t0 = time.time()
    train_truth = el.simulate(train, material=truth, output=out / "train_truth.h5")
    el.simulate(test, material=truth, output=out / "test_truth.h5")
    sag = -train_truth.positions[-1, :, 1].min()
    print(f"simulated both motions in {time.time() - t0:.1f} s; the bar's tip sags "
          f"{1e3 * sag:.1f} mm; positions {train_truth.positions.shape}")

    # 3. What a camera sees.
    obs = el.observe(train_truth.trajectory, visible_fraction=0.13, noise=1e-4,
                     dropout=args.dropout, seed=1, output=out / "obs.h5")
    lost = 1 - obs.valid.mean()  # obs.valid: (T, k) bool, False where a marker was lost
    print(f"observed {obs.num_observed} of {len(train.surface_vertices)} surface vertices over "
          f"{obs.num_frames} frames ({100 * lost:.1f} % of the marker-frames lost)")

    # 4. Learn.
    options = dict(max_iterations=1, forward_fit=0) if args.quick else {}
    t0 = time.time()
    learned = el.learn(DATA / "bar_train.json", out / "obs.h5", output=out / "learned.json",
                       **options)
    recipe = learned.training["recipe"]
    fitted = recipe["parameter_fit"]["fitted"]
    print(f"learned in {time.time() - t0:.1f} s: {learned.description}")
    print(f"  noise {'estimated' if recipe['noise_estimated'] else 'given'}: "
          f"{1e3 * recipe['noise_sigma_m']:.3f} mm; fitted E = {fitted['young']:.4g} Pa, "
          f"nu = {fitted['poisson']:.3f}; chosen: {recipe['chosen_kind']}")
    for c in recipe["candidates"]:
        if c["completed"]:
            print(f"  {c['kind']:>16} {c['iteration']:3d}: validation rms "
                  f"{100 * c['validation_rms_error_m'] / train.size:.4f} % of the size")

    # 5. Evaluate on the test motion.
    report = el.evaluate(test, learned, out / "test_truth.h5", report=out / "report",
                         truth_material=truth)
    print(f"test motion err_L: nominal {report['nominal']['err_L_percent']:.4g} %, learned "
          f"{report['learned']['err_L_percent']:.4g} %; report: {out / 'report' / 'report.html'}")

    # 6. Stress along a uniaxial stretch (lateral stretches held at 1) [kPa], within the
    # stretches the training motion visited (outside them the correction extrapolates).
    trained = learned.training_stretches
    lo, hi = (min(trained["min"]), max(trained["max"])) if trained else (0.98, 1.02)
    s = np.linspace(lo, hi, 5)
    stretches = np.column_stack([s, np.ones_like(s), np.ones_like(s)])
    print(f"first principal stress along a uniaxial stretch in the training range "
          f"[{lo:.4f}, {hi:.4f}]:")
    print("stretch   nominal [kPa]   true [kPa]   learned [kPa]")
    curves = [m.principal_stress(stretches)[:, 0] / 1e3 for m in (train.material, truth, learned)]
    for i, v in enumerate(s):
        print(f"{v:7.4f} {curves[0][i]:15.3f} {curves[1][i]:12.3f} {curves[2][i]:15.3f}")

if __name__ == "__main__":
    main()
