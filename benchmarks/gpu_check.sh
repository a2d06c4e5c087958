#!/usr/bin/env bash
# The GPU checks of issue 40 in one run, for a lent GPU machine (docs/performance.md):
#   pytest    the CUDA tests (pytest -m cuda);
#   expand64  expanding all of Aj's clips onto the six Table 1 characters on cuda in float64, outputs
#             compared with a CPU run of the same pairs (REF) (KEEP=1: kept as OUT/gpu_out.tgz.*);
#   eager     expand64 with the host loop, each solver step launched eagerly (MOTIONLAB_CUDA_GRAPHS=0),
#             instead of the whole step with its rules replayed as one CUDA graph (the default on CUDA:
#             motionlab.retargeting.graphs, motionlab.retargeting.device_loop);
#   fk        benchmarks/bench_fk_product.py (FK's 3x3 products as batched GEMMs or broadcast sums);
#   workers   the same with FEW host worker processes instead of every core but one (FEW: a list,
#             default 4);
#   expand32  the same in float32 (the dtype rule's speed);
#   table1    Table 1 (motionlab evaluate --no-ablations) on cuda, training the network there; the
#             checkpoint is kept (OUT/motionlab_Aj.pt) so the CPU can evaluate the same network;
#   profile   benchmarks/profile_expand_gpu.py (where the solve's time goes; PROFILE_ARGS: its options);
#   notebooks the retargeting notebooks (02, 03, 04, 07) on $DEV as a user with a GPU runs them
#             (MOTIONLAB_DEVICE=$DEV, quick mode, the shipped network: no course data, so nothing is
#             trained), lax: every cell runs and every assert holds (the test suite itself runs
#             them on the CPU, where their stored outputs were made).
# Usage: DATA=mixamo.tar.xz REF=ref_cpu.tar.xz OUT=folder bash benchmarks/gpu_check.sh
# (DATA: a tar of MOTIONLAB_DATA's mixamo/ folder; REF: a tar of a folder ref_cpu/ written on the CPU by
# `python benchmarks/bench_expand.py --clips all --table1-characters --device cpu --skip-per-process
# --skip-ray --keep ref_cpu`; with --clips 10, Table 1's 10 clips, the GPU's outputs of those 60 pairs are
# compared, and the reference takes minutes instead of most of an hour; only the expand stages need it). STAGES names
# the stages, run in that order (default: pytest expand64 expand32 table1). DEV=cpu CLIPS=1 tries the
# script without a GPU.
set -u
export PYTHONPATH=$PWD PYTHONUNBUFFERED=1
PY=${PY:-python3}
DEV=${DEV:-cuda}
CLIPS=${CLIPS:-all}
work=$(mktemp -d)
stage() { echo "=== $(date +%T) $*"; }
expand() {  # expand all pairs on $DEV, compared with the reference; extra options follow
    timeout 200 $PY benchmarks/bench_expand.py --clips "$CLIPS" --table1-characters --device "$DEV" --skip-per-process \
        --skip-ray --reference "$work/ref/ref_cpu" "$@"
}
stage setup
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv 2>/dev/null
$PY -c "import torch, numpy; print('torch', torch.__version__, 'numpy', numpy.__version__, 'cuda', torch.cuda.is_available())"
mkdir -p "$work/data" "$work/ref" "$OUT"
tar xJf "$DATA" -C "$work/data" || exit 1
[ -z "${REF:-}" ] || tar xJf "$REF" -C "$work/ref" || exit 1
export MOTIONLAB_DATA=$work/data
for s in ${STAGES:-pytest expand64 expand32 table1}; do
    stage "$s"
    case $s in
    pytest) timeout 150 $PY -m pytest -m cuda tests/retargeting/test_devices.py -q -p no:cacheprovider 2>&1 | tail -15 ;;
    expand64)
        expand --keep "$work/gpu_out"
        [ -n "${KEEP:-}" ] && (cd "$work" && tar czf - gpu_out | split -b 15M - "$OUT/gpu_out.tgz.") ;;
    eager) MOTIONLAB_CUDA_GRAPHS=0 expand ;;
    fk) timeout 60 $PY benchmarks/bench_fk_product.py --device "$DEV" ;;
    workers) for w in ${FEW:-4}; do expand --host-workers "$w"; done ;;
    expand32) expand --dtype float32 ;;
    table1)
        timeout 300 $PY -m motionlab evaluate --device "$DEV" --checkpoint "$OUT/motionlab_Aj.pt" --no-ablations -q \
            --csv "$OUT/table1_$DEV.csv" 2>&1 | tee "$OUT/table1_$DEV.txt" ;;
    profile) timeout 240 $PY benchmarks/profile_expand_gpu.py --device "$DEV" ${PROFILE_ARGS:-} $( [ "$CLIPS" = all ] || echo --clips "$CLIPS" ) ;;
    notebooks)
        if $PY -c "import nbval, ipykernel" 2>/dev/null; then
            env -u MOTIONLAB_DATA MOTIONLAB_DEVICE="$DEV" MOTIONLAB_QUICK=1 MPLBACKEND=Agg PYVISTA_OFF_SCREEN=true \
                timeout 300 $PY -m pytest --nbval-lax -q -p no:cacheprovider notebooks/02_training_autoencoder.ipynb \
                notebooks/03_latent_iteration.ipynb notebooks/04_playback_and_bone_proportions.ipynb \
                notebooks/07_expanding_a_database.ipynb 2>&1 | tail -15
        else
            echo "notebooks: skipped, nbval or ipykernel is not installed here"
        fi ;;
    *) echo "unknown stage $s (pytest expand64 eager fk workers expand32 table1 profile notebooks)"; exit 2 ;;
    esac
done
stage done
