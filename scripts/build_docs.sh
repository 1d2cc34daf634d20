#!/usr/bin/env bash
# Build the documentation site into docs/_build/html: the pages of docs/, the API reference from the
# docstrings, the scene-key reference from the schema and the gallery (every examples/plot_*.py is run).
# Warnings are errors, as in CI.
#
# Usage (the README's docs command installs the docs extra into .venv and runs this):
#   scripts/build_docs.sh                       the Python of the checkout's .venv if there is one, else python3
#   PYTHON=/path/to/python scripts/build_docs.sh   another Python (it needs the docs extra)
#   scripts/build_docs.sh -D plot_gallery=0     any further arguments go to sphinx-build (here: skip running
#                                               the gallery, for a quick look at the pages)
set -euo pipefail
cd "$(dirname "$0")/.."

if [ -n "${PYTHON:-}" ]; then
    python=$PYTHON
elif [ -x .venv/bin/python ]; then
    python=.venv/bin/python  # where the README's commands install weftsim and its extras
else
    python=python3
fi
"$python" -c 'import sphinx, sphinx_gallery, myst_parser, furo' 2>/dev/null || {
    echo "build_docs: the docs extra is not installed for $python: $python -m pip install -c requirements.lock '.[docs]'" >&2
    exit 2
}
# The gallery runs Exudyn: it must never try to open a window, with or without a display.
export EXUDYN_SUPPRESS_UI_WINDOW_OPEN=1 MPLBACKEND=Agg
start=$(date +%s)
"$python" -m sphinx -W --keep-going -b html docs docs/_build/html "$@"
# Sphinx does not check the #anchors of its own links (the source pages link back to the API pages).
"$python" scripts/check_anchors.py docs/_build/html || {
    echo "build_docs: links to missing anchors (above); after moving pages, stale pages of an earlier build can" \
         "cause this: rm -rf docs/_build and build again" >&2
    exit 1
}
# The equations must show without a network: MathJax from the site, every formula typeset by it offline.
"$python" scripts/check_offline_math.py docs/_build/html || { echo "build_docs: the equations do not show offline" >&2; exit 1; }
echo "build_docs: docs/_build/html/index.html built with $python in $(( $(date +%s) - start )) s" >&2
