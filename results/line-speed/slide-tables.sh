#!/bin/sh
# The exact model's slide tables and the leaner integration step: the build without them and the
# build with them, measured in one run:
#   sh results/line-speed/slide-tables.sh
# c60769e (before) against aa062e1 (after); see compare-commits.sh for what is measured.
exec sh "$(dirname "$0")/compare-commits.sh" c60769e aa062e1
