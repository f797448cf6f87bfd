"""High-frequency energy of a zoom's frames: the variance of the Laplacian
of each frame's luma (Rec. 709 weights on the sRGB values, 0..1). Prints
each frame's energy, then the share of frames after the first whose energy
falls below the first's, in frame order. With `--reference`, the same
frames rendered with a generous fixed count: also the share of frames that
lose more than 5% of their reference's energy, and the worst loss.

usage: python3 bench/detail.py FRAME.png... [--reference REF.png...]
       (the first named is frame 0; references in the same frame order)
"""
import os
import sys

import numpy as np
from PIL import Image

# A loss a film-maker sees as softer detail, past frame-to-frame noise.
LOSS = 0.05


def energy(path):
    rgb = np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0
    luma = rgb @ np.array([0.2126, 0.7152, 0.0722])
    # The 4-neighbour Laplacian over the interior pixels.
    lap = (luma[:-2, 1:-1] + luma[2:, 1:-1] + luma[1:-1, :-2] + luma[1:-1, 2:]
           - 4.0 * luma[1:-1, 1:-1])
    return float(lap.var())


def against_reference(energies, paths):
    if len(paths) != len(energies):
        sys.exit(f"{len(energies)} frames but {len(paths)} references")
    refs = [energy(p) for p in paths]
    losses = [1.0 - e / r for e, r in zip(energies, refs)]
    lost = sum(loss > LOSS for loss in losses)
    worst = max(range(len(losses)), key=lambda i: losses[i])
    name = os.path.basename(paths[worst])
    print("  reference: " + " ".join(f"{r:.5f}" for r in refs))
    print(f"  {lost} of {len(losses)} frames lose more than {LOSS:.0%} of the"
          f" reference's energy (worst: {name}, {losses[worst]:+.1%};"
          f" best {min(losses):+.1%})")


def main(args):
    paths, refs = args, []
    if "--reference" in args:
        at = args.index("--reference")
        paths, refs = args[:at], args[at + 1:]
    energies = [energy(p) for p in paths]
    first, rest = energies[0], energies[1:]
    below = sum(e < first for e in rest)
    print("  " + " ".join(f"{e:.5f}" for e in energies))
    print(f"  {below} of {len(rest)} frames below frame 0's ({below / len(rest):.0%})")
    if refs:
        against_reference(energies, refs)


if __name__ == "__main__":
    main(sys.argv[1:])
