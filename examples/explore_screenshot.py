"""A screenshot of an ``animat explore`` page, as docs/images/explore.png was made.

    PYTHONPATH=build/python .venv/bin/python examples/explore_screenshot.py data/paper_100_generations/dn2 \\
        --run 4 --out docs/images/explore.png

Builds the page of the runs (``animat explore RUN_DIR... --modes``), opens it in headless Chromium
(Debian's ``/usr/bin/chromium`` driven by playwright; scripts/setup.sh installs both), shows frame
``--frame`` of the swim of run ``--run`` and saves the part of the page from the runs table to the swim
and the phase map as a PNG with a ``--colors`` palette (small enough for docs/images).
"""

from __future__ import annotations

import argparse
import io
import os
import tempfile
from pathlib import Path

from PIL import Image

from animat import explore


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="+", metavar="RUN_DIR")
    p.add_argument("--out", type=Path, default=Path("explore.png"))
    p.add_argument("--width", type=int, default=1100, help="browser window width in CSS pixels (default 1100)")
    p.add_argument("--run", type=int, default=0, help="the run shown below the curves (default 0, the first)")
    p.add_argument("--frame", type=int, default=120, help="swim frame shown (default 120)")
    p.add_argument("--colors", type=int, default=224, help="PNG palette size (default 224)")
    p.add_argument("--chromium", default=os.environ.get("ANIMAT_CHROMIUM", "/usr/bin/chromium"))
    args = p.parse_args()
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        page_path = explore.write_page(args.runs, Path(tmp) / "explore.html", modes=True)
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=args.chromium)
            page = browser.new_page(viewport={"width": args.width, "height": 900})
            page.goto(page_path.as_uri())
            page.wait_for_function("window.animatExplore && window.animatExplore.ready")
            page.evaluate(f"animatExplore.selectRun({args.run})")
            page.evaluate(f"animatExplore.setFrame({args.frame})")
            top = page.eval_on_selector("#runs-section", "(e) => e.getBoundingClientRect().top + window.scrollY")
            bottom = page.eval_on_selector(
                "#run-section .row", "(e) => e.getBoundingClientRect().bottom + window.scrollY"
            )
            png = page.screenshot(full_page=True, clip={"x": 0, "y": top, "width": args.width, "height": bottom - top})
            browser.close()
    image = Image.open(io.BytesIO(png)).convert("RGB")
    image = image.quantize(colors=args.colors, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    image.save(args.out, optimize=True)
    print(f"{args.out}: {image.size[0]}x{image.size[1]} px, {args.out.stat().st_size / 1e3:.0f} kB")


if __name__ == "__main__":
    main()
