"""The pictures of docs/views.md (``docs/img/view_*.png``), one per kind, drawn by ``femkit view``'s
own code from bundled cases run at their full size.

Usage (``femkit[view]`` installed; a few minutes on 2 cores)::

    python scripts/view_images.py RUNS_DIR      # run the cases into RUNS_DIR, write docs/img/view_*.png

Each PNG is 1280 pixels wide, quantised to a 256-colour palette (well under 150 KB).
"""

from __future__ import annotations

import argparse
import io
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IMG = ROOT / "docs" / "img"

#: picture -> (case file, --set overrides, view options)
PICTURES = {
    "view_poisson_2d": ("cases/poisson_lshape_adaptive.yaml", {"adaptive__max_dofs": 2000},
                        {"field": "eta", "edges": True}),
    "view_fichera": ("cases/fichera.yaml", {}, {}),
    "view_solid": ("cases/solid_cantilever.yaml", {"output__png": False, "output__gif": False}, {}),
    "view_cloth": ("cases/scenes/hanging_cloth.yaml", {"output__png": False}, {"frame": 12}),
    "view_disk": ("cases/scenes/soft_disk.yaml", {"output__png": False}, {"frame": 18}),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", type=Path, help="where the runs are written")
    args = parser.parse_args()
    from PIL import Image

    from femkit.case import load_case
    from femkit.view import open_view

    for name, (case_file, overrides, options) in PICTURES.items():
        run = args.runs / name
        frame = options.pop("frame", None)
        if options.get("field") == "eta":  # the indicators are in the result, not in its files
            result = load_case(ROOT / case_file, **overrides).run(output_dir=run, quiet=True)
            view = result.plot(size=(1280, 900), **options)
        else:
            if not (run / "result.json").exists():
                load_case(ROOT / case_file, **overrides).run(output_dir=run, quiet=True)
            view = open_view(run, size=(1280, 900), **options)
        view = view.frame(frame) if frame is not None else view
        buf = io.BytesIO()
        Image.fromarray(view.image()).quantize(256, method=Image.Quantize.FASTOCTREE).save(buf, format="PNG", optimize=True)
        (IMG / f"{name}.png").write_bytes(buf.getvalue())
        print(f"{name}.png: {len(buf.getvalue()) / 1024:.0f} KB, {view}")


if __name__ == "__main__":
    main()
