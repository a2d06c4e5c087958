#!/usr/bin/env bash
# The GPU checks of issue 40 in one run, for a lent GPU machine (docs/performance.md):
#   1. the CUDA tests (pytest -m cuda);
#   2. expanding all of Aj's clips onto the six Table 1 characters on cuda in float64, outputs
#      compared with a CPU run of the same pairs (REF), kept as OUT/gpu_out.tgz.*;
#   3. the same in float32 (the dtype rule's speed);
#   4. Table 1 (motionlab evaluate --no-ablations) on cuda, training the network there; the
#      checkpoint is kept (OUT/motionlab_Aj.pt) so the CPU can evaluate the same network.
# Usage: DATA=mixamo.tar.xz REF=ref_cpu.tar.xz OUT=folder bash benchmarks/gpu_check.sh
# (DATA: a tar of MOTIONLAB_DATA's mixamo/ folder; REF: a tar of a folder ref_cpu/ written by
# `motionlab expand ... --device cpu -o ref_cpu`). STAGES picks stages (default: pytest expand64 expand32
# table1; also profile: benchmarks/profile_expand_gpu.py). DEV=cpu CLIPS=1 tries the script without a GPU.
set -u
export PYTHONPATH=$PWD PYTHONUNBUFFERED=1
PY=${PY:-python3}
DEV=${DEV:-cuda}
CLIPS=${CLIPS:-all}
work=$(mktemp -d)
stage() { echo "=== $(date +%T) $*"; }
stage setup
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv 2>/dev/null
$PY -c "import torch, numpy; print('torch', torch.__version__, 'numpy', numpy.__version__, 'cuda', torch.cuda.is_available())"
mkdir -p "$work/data" "$work/ref" "$OUT"
tar xJf "$DATA" -C "$work/data" && tar xJf "$REF" -C "$work/ref" || exit 1
export MOTIONLAB_DATA=$work/data
STAGES=" ${STAGES:-pytest expand64 expand32 table1} "
on() { [[ "$STAGES" == *" $1 "* ]]; }
if on pytest; then
stage pytest -m cuda
timeout 150 $PY -m pytest -m cuda tests/retargeting/test_devices.py -q -p no:cacheprovider 2>&1 | tail -15
fi
if on profile; then
    stage profile
    timeout 240 $PY benchmarks/profile_expand_gpu.py --device "$DEV" $( [ "$CLIPS" = all ] || echo --clips "$CLIPS" )
fi
if on expand64; then
stage expand float64
timeout 200 $PY benchmarks/bench_expand.py --clips "$CLIPS" --table1-characters --device "$DEV" --skip-per-process \
    --skip-ray --reference "$work/ref/ref_cpu" --keep "$work/gpu_out"
(cd "$work" && tar czf - gpu_out | split -b 15M - "$OUT/gpu_out.tgz.")
fi
if on expand32; then
stage expand float32
timeout 150 $PY benchmarks/bench_expand.py --clips "$CLIPS" --table1-characters --device "$DEV" --dtype float32 \
    --skip-per-process --skip-ray --reference "$work/ref/ref_cpu"
fi
if on table1; then
    stage "Table 1 on $DEV (trains the network there)"
    timeout 300 $PY -m motionlab evaluate --device "$DEV" --checkpoint "$OUT/motionlab_Aj.pt" --no-ablations -q \
        --csv "$OUT/table1_$DEV.csv" 2>&1 | tee "$OUT/table1_$DEV.txt"
fi
stage done
