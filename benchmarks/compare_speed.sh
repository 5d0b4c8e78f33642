#!/usr/bin/env bash
# Speed of two checkouts of the library, alternately, in one run (docs/CONTACT_AXES.md):
#
#     benchmarks/compare_speed.sh BEFORE AFTER [ROUNDS]
#
# BEFORE and AFTER are checkouts with their compiled kernels (dolfinx_mortar/_kernels*.so);
# each scene runs as a cold process on one core (taskset -c 0), with PYTHONPATH set to the
# checkout, ROUNDS times (2); it prints "round checkout scene seconds" and leaves each run's
# JSON or CSV next to its log in $TMPDIR (default /tmp), for the figures to be compared.
set -e
before=$(realpath "$1"); after=$(realpath "$2"); rounds=${3:-2}; tmp=${TMPDIR:-/tmp}
export OMP_NUM_THREADS=1
for round in $(seq "$rounds"); do
  for tree in "$before" "$after"; do
    tag=$(basename "$tree")
    for scene in cc h3c h3i; do
      case $scene in
        cc)  args="benchmarks/current_contact_cost.py --refine 1.5 --configurations current --out $tmp/cc_$tag" ;;
        h3c) args="demos/hertz3d.py --refine 1.5 --basis-configuration current --json $tmp/h3c_$tag.json" ;;
        h3i) args="demos/hertz3d.py --refine 1.5 --json $tmp/h3i_$tag.json" ;;
      esac
      start=$(date +%s.%N)
      (cd "$tree" && PYTHONPATH="$tree" taskset -c 0 python3 $args > "$tmp/out_${tag}_$scene.log" 2>&1)
      end=$(date +%s.%N)
      echo "$round $tag $scene $(python3 -c "print(round($end - $start, 2))")"
    done
  done
done
