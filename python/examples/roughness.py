"""The Cornell box with its mirror sphere turned into a metal at four roughness values,
rendered from Python and plotted side by side with Matplotlib.

    pip install ./python matplotlib
    python python/examples/roughness.py [OUT.png] [--spp N] [--size N]

Writes docs/python-roughness.png by default. Renders on the GPU when there is one.
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt
import numpy as np

import glint

ROOT = pathlib.Path(__file__).resolve().parents[2]
ROUGHNESS = (0.0, 0.2, 0.4, 0.7)


def to_display(image, exposure=0.0):
    """Linear radiance to sRGB for Matplotlib, as glint's PNG output does (clamp tonemap)."""
    x = np.clip(image * 2.0**exposure, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", nargs="?", default=ROOT / "docs" / "python-roughness.png")
    parser.add_argument("--spp", type=int, default=128)
    parser.add_argument("--size", type=int, default=192)
    args = parser.parse_args()

    scene = glint.load(ROOT / "scenes" / "cornell.toml")
    figure, axes = plt.subplots(1, len(ROUGHNESS), figsize=(3 * len(ROUGHNESS), 3.3))
    for ax, roughness in zip(axes, ROUGHNESS):
        # Edit the scene in place (checked as the file would be), then render it again.
        scene.materials["mirror"] = {
            "type": "metal",
            "color": [0.95, 0.64, 0.54],  # copper-ish
            "roughness": roughness,
        }
        result = glint.render(scene, spp=args.spp, width=args.size, height=args.size, full=True)
        stats = result.stats
        print(f"roughness {roughness}: {stats['spp']} spp in {stats['seconds']:.2f} s on {stats['device']}")
        ax.imshow(to_display(result.image))
        ax.set_title(f"metal, roughness {roughness}")
        ax.axis("off")
    figure.suptitle(f"glint from Python: the Cornell box, {args.spp} spp per image")
    figure.tight_layout()
    figure.savefig(args.output, dpi=100)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
