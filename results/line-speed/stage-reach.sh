#!/bin/sh
# The slide tables' reach past an edge's ends and round a vertex's whole turn: the build without
# it and the build with it, measured in one run:
#   sh results/line-speed/stage-reach.sh
# f2b485c (before: tables on the edges and vertices' cones only) against 6700b62 (after); see
# compare-commits.sh.
exec sh "$(dirname "$0")/compare-commits.sh" f2b485c 6700b62
