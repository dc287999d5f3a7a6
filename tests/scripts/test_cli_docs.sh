#!/usr/bin/env bash
# The command line agrees with its documentation: every `--help` exits 0 and lists what
# docs/cli.md documents for that command (and no more); `piola --help` names every command;
# every JSON scene snippet in README.md and docs/ passes `piola check`. Checks in cli_docs.py.
set -euo pipefail
exec /usr/bin/python3 "$(dirname "$0")/cli_docs.py"
