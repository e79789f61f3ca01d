#!/usr/bin/env bash
# Coarsening (paper 000 §7.3): learn one homogeneous material on a coarse bar from a layered fine
# bar's motions, and measure err_L on other motions for the nominal, the best homogeneous
# material (fit-parameters) and the learned one.
#
#   examples/09_coarsening/run.sh [OUTPUT_DIR]        (default: out/coarsening)
#
# The executable is $ELASTOLEARN, else build/apps/elastolearn/elastolearn of this repository.
# Needs python3 (its standard library only) for the final table.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
exe="${ELASTOLEARN:-$here/../../build/apps/elastolearn/elastolearn}"
out="${1:-out/coarsening}"
if [[ ! -x "$exe" ]]; then
  echo "run.sh: no elastolearn executable at $exe (build it, or set ELASTOLEARN)" >&2
  exit 2
fi
mkdir -p "$out"
out="$(cd "$out" && pwd)"
SECONDS=0

step() { printf '\n== %s\n' "$*"; }

step "1. the layered fine bar's four motions (the truth: 13056 tets, E = 1e5 / 1e7 Pa layers)"
for motion in train_bend train_twist test_bend test_twist; do
  "$exe" simulate "$here/fine_$motion.json" -o "$out/fine_$motion.h5" -q
done

step "2. each fine motion observed at every vertex of the coarse bar (observe --onto)"
for motion in train_bend train_twist test_bend test_twist; do
  "$exe" observe "$out/fine_$motion.h5" --onto "$here/coarse_$motion.json" --all \
    -o "$out/${motion}_obs.h5"
done

step "3. the training set: the bend and the twist on the coarse bar"
cat > "$out/training.json" <<JSON
{"format": "elastolearn-training/1",
 "motions": [{"scene": "$here/coarse_train_bend.json", "observations": "train_bend_obs.h5"},
             {"scene": "$here/coarse_train_twist.json", "observations": "train_twist_obs.h5"}]}
JSON

step "4. the best homogeneous material: E, nu, alpha0, alpha1 fitted to both motions at once"
"$exe" fit-parameters "$out/training.json" -o "$out/fitted.json" -q

step "5. learn with the default recipe (no options)"
"$exe" learn "$out/training.json" -o "$out/learned.json" -q

step "6. nominal, fitted and learned on the test motions, against the fine motion"
for motion in test_bend test_twist train_bend train_twist; do
  for material in fitted learned; do
    "$exe" evaluate "$here/coarse_$motion.json" --material "$out/$material.json" \
      --truth "$out/${motion}_obs.h5" --json "$out/eval_${motion}_$material.json" -q > /dev/null
  done
done

step "err_L: max vertex error over the motion, % of the bar's diagonal (paper 000 Table 1: 0.2 / 0.5)"
python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
fit = json.load(open(os.path.join(out, "fitted.json")))["material"]
learned = json.load(open(os.path.join(out, "learned.json")))
chosen = learned["training"]["recipe"].get("chosen_kind", "?")
print("fitted: E %.4g Pa, nu %.4f; learned: the recipe chose %s" % (fit["young"], fit["poisson"], chosen))
print("%-12s %10s %10s %10s" % ("motion", "nominal", "fitted", "learned"))
stopped = False
for motion in ("test_bend", "test_twist", "train_bend", "train_twist"):
    runs = {m: json.load(open(os.path.join(out, "eval_%s_%s.json" % (motion, m))))
            for m in ("fitted", "learned")}
    row = [runs["fitted"]["nominal"], runs["fitted"]["learned"], runs["learned"]["learned"]]
    cells = ["%10.4f" % r["err_L_percent"] + ("" if r["completed"] else "*") for r in row]
    stopped = stopped or not all(r["completed"] for r in row)
    print("%-12s %s" % (motion, " ".join(cells)))
if stopped:
    print("(* the simulation stopped early; its error covers the frames before)")
PY
printf 'total %d s; files in %s\n' "$SECONDS" "$out"
