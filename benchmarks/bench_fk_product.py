"""FK's 3×3 products on a device: ``a @ b`` against the broadcast sum CUDA uses (issue 40).

The latent iteration runs :func:`motionlab.retargeting.model.fk_by_level` forward and backward at
every step on every row of a batch. On CUDA its small matrix products are broadcast sums
(``model.summed_product``) instead of batched GEMMs (``a @ b``). This times FK forward and
backward on a batch as wide as the widest of ``expand``'s GPU batches (246 pairs × 111 frames by
default), both ways, device synchronised, and prints the largest difference in positions (cm,
skeleton in metres) and in gradients.

Usage::

    python benchmarks/bench_fk_product.py [--device cuda] [--rows 246] [--frames 111] [--repeats 20]
"""

from __future__ import annotations

import argparse
import time

import torch

from motionlab.core import humanoid
from motionlab.core import quat_torch as tq
from motionlab.retargeting import model
from motionlab.retargeting.devices import pick


def _run(product, q0: torch.Tensor, offsets: torch.Tensor, repeats: int) -> tuple[float, torch.Tensor, torch.Tensor]:
    """Median seconds of one FK forward and backward with ``product``; its positions and gradient."""
    times = []
    for _ in range(repeats + 2):  # the first two warm the device up
        q = q0.clone().requires_grad_()
        _sync(q.device)
        start = time.perf_counter()
        pos = model.fk_by_level(q, offsets, humanoid.PARENTS, product=product)
        pos.square().sum().backward()
        _sync(q.device)
        times.append(time.perf_counter() - start)
    return sorted(times[2:])[len(times[2:]) // 2], pos.detach(), q.grad


def _sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--device", default=None, help="torch device (default: cuda if available, else cpu)")
    ap.add_argument("--rows", type=int, default=246)
    ap.add_argument("--frames", type=int, default=111)
    ap.add_argument("--repeats", type=int, default=20)
    args = ap.parse_args()
    device = pick(args.device)
    gen = torch.Generator().manual_seed(0)
    q0 = tq.normalize(torch.randn(args.rows, args.frames, len(humanoid.PARENTS), 4, dtype=torch.float64, generator=gen))
    offsets = torch.tensor(humanoid.canonical_skeleton().offsets, dtype=torch.float64)
    q0, offsets = q0.to(device), offsets.to(device)
    t_mm, pos_mm, grad_mm = _run(torch.matmul, q0, offsets, args.repeats)
    t_sum, pos_sum, grad_sum = _run(model.summed_product, q0, offsets, args.repeats)
    print(
        f"FK forward + backward on {device}, float64, {args.rows} x {args.frames} frames x {len(humanoid.PARENTS)} joints"
    )
    print(f"  a @ b (batched GEMM)      {1e3 * t_mm:8.2f} ms")
    print(f"  broadcast sum             {1e3 * t_sum:8.2f} ms   ({t_mm / t_sum:.1f}x)")
    print(
        f"  largest difference: positions {100 * (pos_sum - pos_mm).abs().max():.2e} cm, "
        f"gradient {(grad_sum - grad_mm).abs().max():.2e}"
    )


if __name__ == "__main__":
    main()
