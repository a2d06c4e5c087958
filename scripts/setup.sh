#!/usr/bin/env bash
# Create .venv/ with motionlab and everything its tests and notebooks need.
# torch is installed first at a pinned version: on machines that keep its CPU wheel locally
# this avoids downloading the multi-GB CUDA build. Elsewhere, set MOTIONLAB_TORCH_INDEX to
# https://download.pytorch.org/whl/cpu to fetch the CPU build from PyTorch's own index.
# `bash scripts/setup.sh --core` stops after torch, numpy and tqdm: what training the retargeting
# network needs (with PYTHONPATH at the clone; .ci/run starts the training there, then runs this
# script again for the rest).
set -euo pipefail
case "${1:-}" in
  "" | --core) ;;
  *) echo "setup.sh: unknown option '$1' (expected none, or --core)" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
VENV=${MOTIONLAB_VENV:-.venv}
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
PY="$VENV/bin/python"
"$PY" -m pip install -q --upgrade pip
if ! "$PY" -c "import torch" >/dev/null 2>&1; then
  if [ -n "${MOTIONLAB_TORCH_INDEX:-}" ]; then
    "$PY" -m pip install -q torch --index-url "$MOTIONLAB_TORCH_INDEX"
  else
    "$PY" -m pip install -q torch==2.13.0
  fi
fi
if [ "${1:-}" = --core ]; then
  "$PY" -m pip install -q numpy tqdm
  exit 0
fi
"$PY" -m pip install -q -e ".[dev,notebooks,bench,docs,cluster]"
"$PY" -m ipykernel install --sys-prefix --name python3 >/dev/null 2>&1 || true
echo "motionlab is installed in $VENV (activate with: source $VENV/bin/activate)"
