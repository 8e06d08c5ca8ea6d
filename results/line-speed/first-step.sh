#!/bin/sh
# The first step after an event sized from the new segment's rates: the build without it and the
# build with it, measured in one run:
#   sh results/line-speed/first-step.sh
# 16bc4ac (before) against 2c8ac7c (after); see compare-commits.sh.
exec sh "$(dirname "$0")/compare-commits.sh" 16bc4ac 2c8ac7c
