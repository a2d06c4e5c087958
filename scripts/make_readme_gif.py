"""Make the README's GIF: a real Mixamo clip of Aj, motionlab's retargeting onto another
character, and that character's own Mixamo clip, side by side.

    MOTIONLAB_DATA=/path/to/shared/data python scripts/make_readme_gif.py \
        --checkpoint /tmp/motionlab_Aj.pt --target Mousey_m --clip Injured_Walk_Left_Turn

The checkpoint is the network trained on Aj's clips (``motionlab evaluate`` trains it at that
path when it is missing). Needs off-screen rendering (EGL or OSMesa; see the README).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from motionlab import data
from motionlab.core import bvh, preprocess
from motionlab.retargeting import load, retarget
from motionlab.viz import save_gif, side_by_side


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checkpoint", required=True, help="network trained on Aj (see motionlab evaluate)")
    ap.add_argument("--target", default="Mousey_m")
    ap.add_argument("--clip", default="Injured_Walk_Left_Turn")
    ap.add_argument("--out", default="docs/media/retarget_mixamo.gif")
    ap.add_argument("--force", action="store_true")
    args = ap.parse_args()

    source = preprocess.prepare(bvh.load(data.clip_path("mixamo", "Aj", args.clip)), fps=60)
    truth = preprocess.prepare(bvh.load(data.clip_path("mixamo", args.target, args.clip)), fps=60)
    result = retarget(source, truth.skeleton, checkpoint=load(args.checkpoint), method="full")
    generated = result.motion
    source.name, generated.name, truth.name = "Aj (source)", f"{args.target}: motionlab", f"{args.target}: Mixamo"
    print(
        f"{args.clip}: Aj {source.skeleton.height():.2f} m → {args.target} {truth.skeleton.height():.2f} m, "
        f"{result.steps} solver steps ({result.stop_reason}), {result.seconds:.2f} s"
    )
    scene = side_by_side([truth, generated, source], error=False, window_size=(720, 360), off_screen=True)
    path = save_gif(scene, Path(args.out), overwrite=args.force, colors=96)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB)")


if __name__ == "__main__":
    main()
