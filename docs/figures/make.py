"""Make the README's pictures: one of each figure command, the cosim plot and the profiler page.

Run from the repository root with the package installed: python docs/figures/make.py
(headless Chromium for the profiler screenshot; the PNGs are palette-quantised to keep the repo small).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
COMMANDS = {
    "effects.png": "designer plot effects --response k --axis x -o {out}",
    "heatmap.png": "designer plot heatmap -o {out}",
    "loo.png": "designer plot loo -o {out}",
    "space.png": "designer plot space --x width --y height --response k --fix raster=45 --target 0.8 "
    "-o {out}",
    "space_c.png": "designer plot space --response c --target 2e-3 -o {out}",
    "volume.png": "designer plot space --volume --x width --y height --z density --target 0.8 -o {out}",
    "timeseries.png": "designer plot timeseries {tmp}/arm/timeseries.csv -o {out}",
}


def _shrink(png: Path) -> None:
    Image.open(png).convert("RGB").quantize(colors=128, method=Image.Quantize.MEDIANCUT).save(
        png, optimize=True
    )


def _profiler(tmp: Path, out: Path) -> None:
    sys.path.insert(0, str(ROOT / "tests"))
    import cdp

    subprocess.run(
        ["designer", "profile", "--target", "k=0.8", "--target", "c=2e-3", "-o", str(tmp / "p.html")],
        check=True,
    )
    with cdp.Browser(cdp.find_browser(), width=1280, height=800) as browser:
        page = browser.new_page()
        page.viewport(1280, 800)
        page.goto((tmp / "p.html").as_uri())
        page.click("#lock-width")
        page.click("#lock-raster")
        page.click("#maximize")
        page.call(
            "Emulation.setDeviceMetricsOverride", width=1280, height=1640, deviceScaleFactor=1, mobile=False
        )
        page.js("window.scrollTo(0, 0)")
        data = page.call("Page.captureScreenshot", format="png")["data"]
    import base64

    out.write_bytes(base64.b64decode(data))


def main() -> None:
    with tempfile.TemporaryDirectory() as t:
        tmp = Path(t)
        subprocess.run(
            ["designer", "cosim", str(ROOT / "examples/two_link_arm.toml"), "-o", str(tmp / "arm")],
            check=True,
        )
        shutil.copy(tmp / "arm" / "plot.png", HERE / "cosim_plot.png")
        for name, cmd in COMMANDS.items():
            subprocess.run(cmd.format(out=HERE / name, tmp=tmp).split(), check=True)
        _profiler(tmp, HERE / "profiler.png")
    for png in sorted(HERE.glob("*.png")):
        _shrink(png)
        print(f"{png.name}: {png.stat().st_size // 1024} KiB")


if __name__ == "__main__":
    main()
