#!/bin/sh
# The faster exact contact: the build without it and the build with it, measured in one run:
#   sh results/line-speed/contact-speed.sh
# b823114 (before) against afe26bc (after); see compare-commits.sh for what is measured.
exec sh "$(dirname "$0")/compare-commits.sh" b823114 afe26bc
