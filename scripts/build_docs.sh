#!/usr/bin/env bash
# Build the documentation site into docs/_build/html (entry point: docs/_build/html/index.html).
# Notebooks are rendered with their stored outputs (nothing is executed); warnings are errors.
# Needs the `docs` extra: pip install -e ".[docs]" (scripts/setup.sh installs it).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-$( [ -x .venv/bin/python ] && echo .venv/bin/python || echo python3 )}
rm -rf docs/api/generated docs/generated
"$PY" -m sphinx -W --keep-going -q -b html docs docs/_build/html "$@"
echo "site: docs/_build/html/index.html"
