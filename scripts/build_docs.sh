#!/usr/bin/env bash
# Build the documentation site into docs/_build/html: the pages of docs/, the API reference from the
# docstrings and the gallery (every examples/plot_*.py is run). Warnings are errors, as in CI.
#
# Needs the docs extra: pip install -c requirements.lock '.[docs]'
# Usage: scripts/build_docs.sh            (uses python3; PYTHON=.venv/bin/python to choose another)
set -euo pipefail
cd "$(dirname "$0")/.."

python=${PYTHON:-python3}
"$python" -c 'import sphinx, sphinx_gallery, myst_parser, furo' 2>/dev/null || {
    echo "build_docs: the docs extra is not installed for $python: pip install -c requirements.lock '.[docs]'" >&2
    exit 2
}
# The gallery runs Exudyn: it must never try to open a window, with or without a display.
export EXUDYN_SUPPRESS_UI_WINDOW_OPEN=1 MPLBACKEND=Agg
start=$(date +%s)
"$python" -m sphinx -W --keep-going -b html docs docs/_build/html "$@"
echo "build_docs: docs/_build/html/index.html built in $(( $(date +%s) - start )) s" >&2
