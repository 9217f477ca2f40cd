"""Follow-up of the render study: is UNIFORM's deficit a bias or a heavy tail?

Runs in Blender like render_study.py (through tests/blender/run_test.py) after it, and
adds an "extra_checks" entry to render_study.json (render_study_report.py puts
it in the markdown). It renders, on the same scene and seed 7 (not used by the study):
  * UNIFORM at UNIFORM_SPP samples with the study's 4 bounces, compared with the study's
    reference (Hairis ANALYTIC + Cycles);
  * ANALYTIC at ANALYTIC_SPP and UNIFORM at UNIFORM_SPP with 1 bounce (one hair-sampled
    bounce, no products of sampled weights), compared with each other.
"""

import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # the repository
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
OUT = os.environ.get("HAIRIS_STUDY_OUT", HERE)
UNIFORM_SPP = int(os.environ.get("HAIRIS_CHECK_UNIFORM_SPP", "2048"))
ANALYTIC_SPP = int(os.environ.get("HAIRIS_CHECK_ANALYTIC_SPP", "512"))
SEED = 7


def channel_means(strategy, samples, bounces):
    """Renders ``strategy`` on the study's scene; returns (image, seconds)."""
    scene = helpers.make_compare_scene(samples, bounces, strategy, resolution=(64, 48))
    image, seconds = helpers.render_pixels(scene, "HAIRIS", SEED, ARGS.workdir)
    print("%s %d spp, %d bounces: %.1f s" % (strategy, samples, bounces, seconds), flush=True)
    return image, seconds


def main():
    """Renders the three images and records the relative differences."""
    path = os.path.join(OUT, "render_study.json")
    with open(path) as source:
        results = json.load(source)
    reference = np.array(results["reference"]["channel_mean"])
    uniform4, t_u4 = channel_means("UNIFORM", UNIFORM_SPP, 4)
    analytic1, t_a1 = channel_means("ANALYTIC", ANALYTIC_SPP, 1)
    uniform1, t_u1 = channel_means("UNIFORM", UNIFORM_SPP, 1)
    mean = {k: v.reshape(-1, 3).mean(axis=0) for k, v in
            (("u4", uniform4), ("a1", analytic1), ("u1", uniform1))}
    checks = [
        {"what": "UNIFORM %d spp, 4 bounces, seed %d, against the study's reference"
                 % (UNIFORM_SPP, SEED),
         "seconds": t_u4, "relative_difference": (mean["u4"] / reference - 1).tolist()},
        {"what": "UNIFORM %d spp against ANALYTIC %d spp, 1 bounce, seed %d"
                 % (UNIFORM_SPP, ANALYTIC_SPP, SEED),
         "seconds": [t_u1, t_a1], "relative_difference": (mean["u1"] / mean["a1"] - 1).tolist(),
         "relative_rmse_between": float(np.sqrt(np.mean((uniform1 - analytic1) ** 2))
                                        / analytic1.mean())},
    ]
    for check in checks:
        print(check, flush=True)
    results["extra_checks"] = checks
    with open(path, "w") as out:
        json.dump(results, out, indent=1)
    sys.exit(0)


main()
