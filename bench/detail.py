"""High-frequency energy of a zoom's frames: the variance of the Laplacian
of each frame's luma (Rec. 709 weights on the sRGB values, 0..1), and the
share of frames after the first whose energy falls below the first's, in
frame order. Prints each frame's energy, then the share.

usage: python3 bench/detail.py FRAME.png...   (the first named is frame 0)
"""
import sys

import numpy as np
from PIL import Image


def energy(path):
    rgb = np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0
    luma = rgb @ np.array([0.2126, 0.7152, 0.0722])
    # The 4-neighbour Laplacian over the interior pixels.
    lap = (luma[:-2, 1:-1] + luma[2:, 1:-1] + luma[1:-1, :-2] + luma[1:-1, 2:]
           - 4.0 * luma[1:-1, 1:-1])
    return float(lap.var())


def main(paths):
    energies = [energy(p) for p in paths]
    first, rest = energies[0], energies[1:]
    below = sum(e < first for e in rest)
    print(" ".join(f"{e:.5f}" for e in energies))
    print(f"  {below} of {len(rest)} frames below frame 0's ({below / len(rest):.0%})")


if __name__ == "__main__":
    main(sys.argv[1:])
