#!/bin/sh
# The vertex slide tables (a disc pin riding round a vertex served by a table): the build without
# them and the build with them, measured in one run:
#   sh results/line-speed/vertex-tables.sh
# 5ed821d (before: edge tables only) against f2b485c (after); see compare-commits.sh.
exec sh "$(dirname "$0")/compare-commits.sh" 5ed821d f2b485c
