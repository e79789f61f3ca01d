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


def observe(trajectory, *, visible_fraction=None, vertices=None, all_vertices=False, onto=None,
            noise=0.0, dropout=0.0, dropout_burst=5.0, seed=1, output=None):
    """Observe some surface vertices of a trajectory, as ``elastolearn observe``.

    trajectory: a ``Trajectory`` (with tets, e.g. ``simulate(...).trajectory``) or the path of a
    trajectory file. Give exactly one of visible_fraction (in (0, 1], spread over the surface by
    farthest-point sampling), vertices (an int array of vertex ids, or the path of a text file
    of them, as ``--vertices FILE``) and all_vertices=True (every vertex, as ``--all``). onto: a
    ``Scene`` or scene file whose mesh's vertices are observed instead, each interpolated in the
    trajectory mesh's rest tetrahedron that contains it (``--onto``, e.g. a coarse mesh). noise: Gaussian standard deviation per coordinate [m].
    dropout: lost markers, the fraction in [0, 1) of (frame, vertex) entries lost in occlusion
    bursts of mean length dropout_burst frames (>= 1); lost entries are False in ``valid`` and NaN
    in ``positions``. seed: of the vertex choice, the noise and the dropout. output: also write
    the HDF5 observation file.

    Returns an ``Observation`` (vertex_ids (k,), positions (T, k, 3), valid (T, k), dt, metadata).
    """
    return _elastolearn.observe(trajectory, visible_fraction=visible_fraction,
                                vertices=vertices, all_vertices=all_vertices, onto=onto,
                                noise=noise, dropout=dropout,
                                dropout_burst=dropout_burst, seed=seed, output=output)


def learn(scene, observations=None, *, clouds=None, output=None, checkpoint=None, resume=False,
          report=None, truth_material=None, verbose=False, **options):
    """Learn a material from observations with the one recipe, as ``elastolearn learn``.

    scene: the path of a scene file (its material is the nominal) with ``observations`` the path
    of its observation file (or ``clouds`` the path of its point-cloud file, as ``--clouds``:
    tracked, then learned from), or the path of a training-set file (then neither).
    output: also write the learned material file. checkpoint: the file written after every
    iteration (default: OUTPUT.checkpoint.json when output is given, none otherwise).
    resume: continue from that checkpoint (same scene, observations and options, spelled as
    before). report: write the learning report into that folder (docs/report.md), with the
    correction against ``truth_material`` (a ``Material`` or its file) when given.
    verbose: print the recipe's stages and one line per iteration.

    options (keyword, the command line's flags with underscores; ``learn_options()`` lists them;
    a flag is a bool): noise (σ [m], None: estimated), validation_fraction, no_parameter_fit,
    parameter_fit_iterations, max_iterations, patience, free_halvings, no_backtrack,
    no_stability_cuts, modes,
    pod_stride, full_space, pod_forward_only, kernels, position_weight, space_time_iterations,
    regularization, reconstruction ("normal_equations" | "lsqr"), frame_stride,
    unprojected_reconstruction, full_space_weight, no_damping, linear_tail,
    damping_regularization, continuation ("bounded_softening" | "smooth_expansion" |
    "smooth_clamp"), smoothness, seed, forward_fit, forward_fit_tolerance, damping_prior,
    elastic_prior, kernel_smoothing, stress_kernels, no_neo_hookean_tail, no_mass_damping,
    damping_quadratic_tail,
    allow_rest_stress, no_network (stage 5 off: keep the RBF), network_kind,
    network_motion_scales, network_samples, network_rate_jitter.

    Returns the learned ``Material``; ``material.training["recipe"]`` holds what the recipe
    decided (noise, parameter fit, candidates and their validation errors, the choice).
    Ctrl-C stops between stages (KeyboardInterrupt); the same call with resume=True continues.
    """
    return _elastolearn.learn(scene, observations, clouds=clouds, output=output,
                              checkpoint=checkpoint,
                              resume=resume, report=report, truth_material=truth_material,
                              verbose=verbose, **options)


def learn_options():
    """The names of ``learn``'s keyword options."""
    return _elastolearn.learn_options()


def evaluate(scene, material, truth, *, output=None, json=None, solver=None, report=None,
             truth_material=None, progress=False):
    """Compare the nominal and a learned material with a true trajectory, as ``elastolearn
    evaluate`` (paper 000 Table 1's err_L).

    scene: a ``Scene`` or scene file (its material is the nominal). material: a ``Material`` or
    material file. truth: a ``Trajectory`` or trajectory file of the scene's motion. output: also
    write the learned material's trajectory (HDF5). json: also write the returned report there.
    solver: "cholmod", "cg" or "eigen-ldlt" (overrides the scene's). report: a folder for the
    report (report.html, plots, summary.json; docs/report.md). truth_material: the true
    ``Material`` or material file, plotted in the report (needs report).
    progress: print a progress line on stderr.

    Returns the report ``evaluate --json`` writes, as a dict: ``report["nominal"]`` and
    ``report["learned"]`` hold ``err_L_percent``, ``mean_percent``, ``rms_percent``,
    ``max_error`` [m], ...; ``report["improvement"]["err_L"]`` the ratio.
    """
    return _elastolearn.evaluate(scene, material, truth, output=output, json=json, solver=solver,
                                 report=report, truth_material=truth_material, progress=progress)
