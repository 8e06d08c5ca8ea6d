#!/bin/sh
# Before/after the first step after an event sized from the new segment's rates (issue 15 item 1),
# both measured in one run:
#   sh results/line-speed/first-step.sh
# 16bc4ac (before) against 2c8ac7c (after); see compare-commits.sh.
exec sh "$(dirname "$0")/compare-commits.sh" 16bc4ac 2c8ac7c
