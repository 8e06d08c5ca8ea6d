#!/bin/sh
# The stick tables: the build without them and the build with them, measured in one run:
#   sh results/line-speed/stick-tables.sh
# 4db9b7c (before: slide tables only) against 7d8d287 (after: stick tables as well); see
# compare-commits.sh.
exec sh "$(dirname "$0")/compare-commits.sh" 4db9b7c 7d8d287
