#!/bin/sh
# Before/after the exact model's slide tables and the leaner integration step (issue 15 item 1),
# both measured in one run:
#   sh results/line-speed/slide-tables.sh
# c60769e (before) against aa062e1 (after); see compare-commits.sh for what is measured.
exec sh "$(dirname "$0")/compare-commits.sh" c60769e aa062e1
