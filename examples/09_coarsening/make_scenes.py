#!/usr/bin/env python3
"""Writes the scene files of examples/09_coarsening (standard library only):

  fine_<motion>.json    the layered bar, 34 x 8 x 8 cells, E = 1e5 and 1e7 Pa in alternating
                        layers one fine cell (5 mm) thick across the bar's long axis (the truth)
  coarse_<motion>.json  the same bar, 17 x 4 x 4 cells (each cell spans a soft and a stiff layer),
                        one homogeneous corotated nominal, E = the harmonic mean of the two

for the motions train_bend, train_twist, test_bend and test_twist. The bar is clamped at x = 0 and
starts at rest shape with a velocity field (scene "initial": "velocity"), then vibrates freely:
the field is linear in position, so both meshes start from the same motion at their shared
vertices, and nothing else (no load split over different vertex sets) differs between them.

  python3 make_scenes.py [OUTPUT_DIR]      (default: this script's folder)
"""
import json
import os
import sys

SIZE = [0.17, 0.04, 0.04]  # m
FINE_CELLS = [34, 8, 8]
COARSE_CELLS = [17, 4, 4]
SOFT, STIFF = 1e5, 1e7  # Pa
POISSON = 0.4
DENSITY = 1000
# A plain guess from the layers alone: the harmonic mean 2 / (1/E_soft + 1/E_stiff), the modulus
# of equal layers in series along the axis (the Reuss bound). The arithmetic mean (the Voigt
# bound, 5.05e6 Pa) is 25x stiffer still; README.md says what the recipe does with it.
NOMINAL_YOUNG = 2 / (1 / SOFT + 1 / STIFF)
DT = 1e-3
FRAMES = 200
AXIS = [SIZE[0] / 2, SIZE[1] / 2, SIZE[2] / 2]  # a point on the bar's long axis
CLAMP = [0.0, SIZE[1] / 2, SIZE[2] / 2]  # the centre of the clamped face

MOTIONS = {
    "train_bend": {"initial": {"type": "velocity", "velocity": [0, 0.3, 0]},
                   "what": "training bend: every free vertex starts at 0.3 m/s along y"},
    "train_twist": {"initial": {"type": "velocity", "angular_velocity": [20, 0, 0], "center": AXIS},
                    "what": "training twist: the bar starts spinning about its long axis at 20 rad/s"},
    "test_bend": {"initial": {"type": "velocity", "angular_velocity": [0, -2.0, 2.5], "center": CLAMP},
                  "what": "test bend: the bar starts turning about its clamped face's centre (2 and 2.5 rad/s about "
                          "-y and z): a velocity growing along the bar, tip 0.42 m/s along y and 0.34 m/s along z"},
    "test_twist": {"initial": {"type": "velocity", "angular_velocity": [-30, 0, 0], "center": AXIS},
                   "what": "test twist: the bar starts spinning the other way, 1.5x faster (-30 rad/s)"},
}


def scene(name, motion, fine):
    material = {"model": "corotated", "young": SOFT if fine else NOMINAL_YOUNG, "poisson": POISSON,
                "density": DENSITY}
    if fine:
        h = SIZE[0] / FINE_CELLS[0]
        material["regions"] = [{"select": {"layers": {"axis": "x", "period": 2 * h, "start": h,
                                                      "thickness": h}},
                                "young": STIFF}]
    what = motion["what"] + (". The layered fine bar (the truth)." if fine else
                             ". The coarse bar with its homogeneous nominal (E = the harmonic mean of the layers').")
    return {"format": "elastolearn-scene/1",
            "name": ("fine-" if fine else "coarse-") + name.replace("_", "-"),
            "description": what,
            "mesh": {"type": "box", "size": SIZE, "cells": FINE_CELLS if fine else COARSE_CELLS},
            "material": material,
            "fixed": [{"min": "x"}],
            "initial": motion["initial"],
            "time": {"dt": DT, "frames": FRAMES},
            "solver": {"linear": "cholmod"}}


def dumps(document):
    """One top-level key per line."""
    return "{\n" + ",\n".join("  " + json.dumps(k) + ": " + json.dumps(v) for k, v in document.items()) + "\n}\n"


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    os.makedirs(out, exist_ok=True)
    for name, motion in MOTIONS.items():
        for fine in (True, False):
            path = os.path.join(out, ("fine_" if fine else "coarse_") + name + ".json")
            with open(path, "w") as f:
                f.write(dumps(scene(name, motion, fine)))


if __name__ == "__main__":
    main()
