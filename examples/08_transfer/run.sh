#!/usr/bin/env bash
# Transfer: learn a material on a ball, drive the elephant with it, and measure err_L against the
# elephant's ground truth for the nominal, the fitted-parameter baseline and the learned material.
#
#   examples/08_transfer/run.sh [OUTPUT_DIR]        (default: out/transfer)
#
# The executable is $ELASTOLEARN, else build/apps/elastolearn/elastolearn of this repository.
# Needs python3 (its standard library only) for two small JSON steps.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
exe="${ELASTOLEARN:-$here/../../build/apps/elastolearn/elastolearn}"
out="${1:-out/transfer}"
if [[ ! -x "$exe" ]]; then
  echo "run.sh: no elastolearn executable at $exe (build it, or set ELASTOLEARN)" >&2
  exit 2
fi
mkdir -p "$out"
SECONDS=0

step() { printf '\n== %s\n' "$*"; }

step "1. the ball's training motion, simulated with the true material (the 'real' ball)"
"$exe" simulate "$here/ball_train.json" --material "$here/truth.json" -o "$out/ball_truth.h5" -q

step "2. what a camera sees: 13 % of the ball's surface vertices"
"$exe" observe "$out/ball_truth.h5" --visible-fraction 0.13 -o "$out/ball_obs.h5"

step "3. learn on the ball with the default recipe (no options)"
"$exe" learn "$here/ball_train.json" --observations "$out/ball_obs.h5" -o "$out/learned.json" -q

# The fitted-parameter baseline is the recipe's own stage 2: the learned file's nominal (E, ν, α₀,
# α₁ as fitted, training.recipe.parameter_fit.fitted) without the correction.
python3 - "$out/learned.json" "$out/fitted.json" <<'EOF'
import json, sys
learned = json.load(open(sys.argv[1]))
fit = learned["training"]["recipe"]["parameter_fit"]["fitted"]
material = learned["material"]
assert material["young"] == fit["young"] and material["poisson"] == fit["poisson"], \
    "the learned file's nominal is not the recipe's fitted one"
json.dump({"format": "elastolearn-material/1", "material": material, "correction": None,
           "training": {"note": "the fitted-parameter baseline: " + sys.argv[1]
                        + " without its correction (training.recipe.parameter_fit.fitted)"}},
          open(sys.argv[2], "w"), indent=2)
EOF

step "4. the elephant's own motion, simulated with the true material (its ground truth)"
"$exe" simulate "$here/elephant_test.json" --material "$here/truth.json" \
  -o "$out/elephant_truth.h5" -q

step "5. the elephant driven by the learned (transferred) material, and by the fitted baseline"
"$exe" evaluate "$here/elephant_test.json" --material "$out/learned.json" \
  --truth "$out/elephant_truth.h5" --json "$out/elephant_learned.json" -q
"$exe" evaluate "$here/elephant_test.json" --material "$out/fitted.json" \
  --truth "$out/elephant_truth.h5" --json "$out/elephant_fitted.json" -q

step "transfer ball -> elephant: err_L on the elephant (max vertex error over all frames, % of its size)"
python3 - "$out/elephant_learned.json" "$out/elephant_fitted.json" "$out/learned.json" <<'EOF'
import json, sys
learned_run, fitted_run = (json.load(open(p)) for p in sys.argv[1:3])
fit = json.load(open(sys.argv[3]))["training"]["recipe"]["parameter_fit"]["fitted"]
rows = [("nominal (corotated, the scene's)", learned_run["nominal"]),
        ("fitted baseline (E %.3g Pa, nu %.3f)" % (fit["young"], fit["poisson"]), fitted_run["learned"]),
        ("learned on the ball (transferred)", learned_run["learned"])]
print("%-40s %10s %10s" % ("material", "err_L [%]", "rms [%]"))
for name, run in rows:
    print("%-40s %10.2f %10.3f%s" % (name, run["err_L_percent"], run["rms_percent"],
                                     "" if run["completed"] else "  (stopped early)"))
cover = learned_run.get("stretches")
if cover:
    print("elephant stretch samples outside the ball's training stretches: %.2f %%"
          % (100 * cover["fraction_outside"]))
EOF
printf 'total %d s; files in %s\n' "$SECONDS" "$out"
