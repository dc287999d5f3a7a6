#!/usr/bin/env bash
# Examples with self-collision (and a shell in contact with a solid), killed at several
# renames of their output and resumed, give frames byte-identical to an uninterrupted run.
# The checks live in run_resume_examples.py.
set -euo pipefail
exec python3 "$(dirname "$0")/run_resume_examples.py"
