#!/usr/bin/env bash
# Runs killed at every rename of their output, and at random moments, resume to frames
# byte-identical to an uninterrupted run; foreign, damaged or other-version checkpoints are
# refused or skipped. The checks live in run_resume.py.
set -euo pipefail
exec python3 "$(dirname "$0")/run_resume.py"
