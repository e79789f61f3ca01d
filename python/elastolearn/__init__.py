"""elastolearn: data-driven simulation of elastic solids, from Python.

The compiled module ``elastolearn._elastolearn`` calls the C++ library; this package re-exports
it with documented keyword arguments. Arrays are numpy float64 (positions ``(T, n, 3)``,
stretches and stresses ``(m, 3)``) and int32 (vertex ids, tets). Library errors raise
``elastolearn.InputError`` (a ``ValueError``) with the message the command line prints, naming
the file or field. See docs/python.md.
"""

from . import _elastolearn
from ._elastolearn import (  # noqa: F401  (re-exported)
    InputError,
    InternalError,
    Material,
    Observation,
    Scene,
    Simulation,
    Trajectory,
    __version__,
    read_observations,
    read_trajectory,
    write_observations,
    write_trajectory,
)

__all__ = [
    "InputError", "InternalError", "Material", "Observation", "Scene", "Simulation", "Trajectory",
    "evaluate", "learn", "learn_options", "load_material", "load_scene", "observe",
    "read_observations", "read_trajectory", "simulate", "write_observations", "write_trajectory",
]


def load_scene(path):
    """Read and validate a scene file (elastolearn-scene/1 JSON); same as ``Scene.load``."""
    return Scene.load(path)


def load_material(path):
    """Read and validate a material file (elastolearn-material/1 JSON); same as ``Material.load``."""
    return Material.load(path)


def simulate(scene, *, frames=None, material=None, solver=None, output=None, every=1,
             progress=False):
    """Simulate a scene, as ``elastolearn simulate``.

    scene: a ``Scene`` or the path of a scene file.
    frames: number of steps (default: the scene's). material: a ``Material`` or a material file
    that replaces the scene's (``--material``). solver: "cholmod", "cg" or "eigen-ldlt".
    output: also write the HDF5 trajectory there (the file the command line writes).
    every: keep every k-th state. progress: print a progress line on stderr.

    Returns a ``Simulation``: ``positions`` (T, n, 3) [m], ``velocities``, ``time`` (T,),
    ``trajectory`` (a ``Trajectory``), ``completed``, ``message``, ``seconds``. A simulation that
    diverges keeps the frames before it, sets ``completed`` False and warns (RuntimeWarning).
    """
    return _elastolearn.simulate(scene, frames=frames, material=material, solver=solver,
                                 output=output, every=every, progress=progress)


def observe(trajectory, *, visible_fraction=None, vertices=None, noise=0.0, seed=1, output=None):
    """Observe some surface vertices of a trajectory, as ``elastolearn observe``.

    trajectory: a ``Trajectory`` (with tets, e.g. ``simulate(...).trajectory``) or the path of a
    trajectory file. Give exactly one of visible_fraction (in (0, 1], spread over the surface by
    farthest-point sampling) and vertices (an int array of vertex ids). noise: Gaussian standard
    deviation per coordinate [m]. seed: of the vertex choice and the noise. output: also write
    the HDF5 observation file.

    Returns an ``Observation`` (vertex_ids (k,), positions (T, k, 3), dt, metadata).
    """
    return _elastolearn.observe(trajectory, visible_fraction=visible_fraction,
                                vertices=vertices, noise=noise, seed=seed, output=output)


def learn(scene, observations=None, *, output=None, verbose=False, **options):
    """Learn a material from observations with the one recipe, as ``elastolearn learn``.

    scene: the path of a scene file (its material is the nominal) with ``observations`` the path
    of its observation file, or the path of a training-set file (then no observations).
    output: also write the learned material file. verbose: print the recipe's stages and one
    line per iteration.

    options (keyword, the command line's flags with underscores; ``learn_options()`` lists them):
    noise (σ [m], None: estimated), validation_fraction, fit_parameters (bool),
    parameter_fit_iterations, max_iterations, patience, free_halvings, modes, pod_stride,
    full_space, kernels, position_weight, space_time_iterations, regularization,
    reconstruction ("normal_equations" | "lsqr"), frame_stride, fit_damping, quadratic_tail,
    damping_regularization, seed, forward_fit, damping_prior, elastic_prior, kernel_smoothing,
    energy_kernels, network (default True: stage 5), network_kind, network_motion_scales,
    network_samples.

    Returns the learned ``Material``; ``material.training["recipe"]`` holds what the recipe
    decided (noise, parameter fit, candidates and their validation errors, the choice).
    Ctrl-C stops between stages (KeyboardInterrupt); resuming needs the command line.
    """
    return _elastolearn.learn(scene, observations, output=output, verbose=verbose, **options)


def learn_options():
    """The names of ``learn``'s keyword options."""
    return _elastolearn.learn_options()


def evaluate(scene, material, truth, *, output=None, progress=False):
    """Compare the nominal and a learned material with a true trajectory, as ``elastolearn
    evaluate`` (paper 000 Table 1's err_L).

    scene: a ``Scene`` or scene file (its material is the nominal). material: a ``Material`` or
    material file. truth: a ``Trajectory`` or trajectory file of the scene's motion. output: also
    write the learned material's trajectory (HDF5).

    Returns the report ``evaluate --json`` writes, as a dict: ``report["nominal"]`` and
    ``report["learned"]`` hold ``err_L_percent``, ``mean_percent``, ``rms_percent``,
    ``max_error`` [m], ...; ``report["improvement"]["err_L"]`` the ratio.
    """
    return _elastolearn.evaluate(scene, material, truth, output=output, progress=progress)
