#!/usr/bin/env bash
# Build the documentation site into docs/_build/html (entry point: docs/_build/html/index.html).
# Notebooks are rendered with their stored outputs (nothing is executed); warnings are errors.
# Needs the `docs` extra: pip install -e ".[docs]" (scripts/setup.sh installs it), and node + npm
# with the npm registry the first time (three.js for the web players: scripts/vendor_three.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-$( [ -x .venv/bin/python ] && echo .venv/bin/python || echo python3 )}
rm -rf docs/api/generated docs/generated
bash scripts/vendor_three.sh   # three.js for the web players (npm, once; reused while its version stays)
# the doctree cache goes beside the site, not into it (it is not part of what is published)
"$PY" -m sphinx -W --keep-going -q -b html -d docs/_build/doctrees docs docs/_build/html "$@"
echo "site: docs/_build/html/index.html"
