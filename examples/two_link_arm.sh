#!/bin/sh
# The two-link arm with joints designed by `designer suggest`, end to end:
#  1. ask for k = 0.8 N/mm on the x axis at the arm's joint length of 24 mm; the export takes it to
#     the theta axis with the PRB model, K = k (0.85 L)^2 = 0.8 N/mm * (20.4 mm)^2 ~ 333 N.mm/rad;
#  2. two_link_arm.toml takes its joints from that suggestion (candidates 1 and 2), exported on the fly;
#  3. co-simulate the arm with the joint FMUs and validate against MuJoCo's in-engine spring-damper.
# Run: sh examples/two_link_arm.sh [results folder]
set -eu
here=$(dirname "$0")
out=${1:-results/two_link_arm}
designer suggest --k 0.8 --fix length=24 --top 3 --json > "$here/suggestion.json"
designer cosim "$here/two_link_arm.toml" -o "$out" --validate
