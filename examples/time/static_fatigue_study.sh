#!/bin/bash
# Times to failure of static_fatigue.toml's specimen against the stress ratio, over
# seeds (docs/time.md): for each seed, the short-term strength by bisection (the
# load put on at once, law = "softening", a solve stage until equilibrium: at rest
# or not), then the specimen held at 0.9, 0.85 and 0.8 of it with its bonds
# corroding, for at most 100 years of creep time.
#   bash examples/time/static_fatigue_study.sh [bbm] [out]      (about 10 minutes)
set -eu
bbm=${1:-./build/apps/bbm}
out=${2:-out/static_fatigue}
here=$(dirname "$0")
mkdir -p "$out"
# The example with a seed, a load (MPa) and, for the short-term test, a softening
# law and a solve stage.
model() { # seed load short|creep
    local text
    text=$(sed -e "s/seed = 1 }/seed = $1 }/" -e "s/syy = -22e6/syy = -$2e6/" \
        -e 's/duration = 3.156e7/duration = 3.156e9/' -e 's/max_steps = 2000000/max_steps = 3000000/' \
        "$here/static_fatigue.toml")
    if [ "$3" = short ]; then
        text=$(echo "$text" | sed -e 's/^law = "stress_corrosion"/law = "softening"/' -e '/^corrosion_/d' \
            -e 's/^type = "creep"/type = "solve"\nuntil = "equilibrium"/' -e '/^duration = /d' \
            -e 's/^max_steps = 3000000/max_steps = 100000/')
    fi
    echo "$text"
}
holds() { # file: the run ended at rest
    "$bbm" run "$1" --out "$out/run" > "$out/run.log" 2>&1 || return 1
    python3 -c "import json, sys; s = json.load(open('$out/run/summary.json'))
sys.exit(0 if s['complete'] and s['stages'][-1]['verdict']['kind'].startswith('equilibrium') else 1)"
}
echo "seed,short_term_MPa,ratio,load_MPa,time_to_failure_s,cracks_tensile,cracks_shear" > "$out/times.csv"
for seed in 1 2 3; do
    lo=18 hi=30
    while python3 -c "import sys; sys.exit(0 if $hi - $lo > 0.25 else 1)"; do
        mid=$(python3 -c "print(round(($lo + $hi) / 2, 3))")
        model $seed $mid short > "$out/short.toml"
        if holds "$out/short.toml"; then lo=$mid; else hi=$mid; fi
    done
    for ratio in 0.9 0.85 0.8; do
        load=$(python3 -c "print(round($ratio * $lo, 3))")
        model $seed $load creep > "$out/creep.toml"
        "$bbm" run "$out/creep.toml" --out "$out/seed${seed}_$ratio" > "$out/seed${seed}_$ratio.log" 2>&1 || true
        python3 - "$out/seed${seed}_$ratio" $seed $lo $ratio $load >> "$out/times.csv" <<'PY'
import json, sys
d, seed, strength, ratio, load = sys.argv[1:]
s = json.load(open(d + "/summary.json"))
t = s["creep"].get("failed_at", "none in 100 years")
print(f"{seed},{strength},{ratio},{load},{t},{s['cracks']['tensile']},{s['cracks']['shear']}")
PY
        tail -1 "$out/times.csv"
    done
done
