"""Peak memory of `onestroke vectorize` on very large scans (issue 14: up to 300 Mpx are read
downscaled without holding the full image in memory).

Generates seeded scans (a smooth closed pen line on slightly grey paper, the line about
1.5 mm wide as at 1200 dpi) as 1-bit, gray and RGB PNG, a Group 4 (1-bit) and an LZW (gray)
TIFF and a JPEG, then runs `onestroke vectorize` on each in a child process and prints its
peak RSS (the child's VmHWM), CPU seconds (user + system) and exit code. The scans are written to --folder and deleted
afterwards unless --keep; they are never committed.

    python -m benchmarks.large_scans                       # 139 and 300 Mpx, every kind
    python -m benchmarks.large_scans --mpx 139 --kinds png-l,png-rgb --keep
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

if __name__ == "__main__" and Path(sys.path[0]).resolve() == Path(__file__).resolve().parent:
    sys.path[0] = str(Path(__file__).resolve().parents[1])  # run as a file: see benchmarks/__init__.py

import numpy as np
from PIL import Image, ImageDraw

KINDS = ("png-1", "png-l", "png-rgb", "tiff-1", "tiff-l", "jpeg-rgb")
ROOT = Path(__file__).resolve().parents[1]
Image.MAX_IMAGE_PIXELS = None  # these scans are this large on purpose


def scan_size(mpx: float) -> tuple[int, int]:
    """A4 proportions (210 x 297) with at most `mpx` million pixels: (width, height) px."""
    height = int(np.sqrt(mpx * 1e6 * 297 / 210))
    return int(mpx * 1e6 // height), height


def draw_scan(size: tuple[int, int], mode: str, seed: int) -> Image.Image:
    """A seeded closed pen line (a wobbly loop with a crossing) on paper, in `mode`."""
    rng = np.random.default_rng(seed)
    w, h = size
    t = np.linspace(0.0, 2.0 * np.pi, 4000)
    radius = 1.0 + sum(rng.uniform(0.03, 0.12) * np.sin(k * t + rng.uniform(0, 2 * np.pi)) for k in (2, 3, 5))
    x = w / 2 + 0.35 * w * radius * np.cos(t) * np.cos(t / 2 + 0.4)
    y = h / 2 + 0.35 * h * radius * np.sin(2 * t) / 1.2
    paper, ink = {"1": (1, 0), "L": (242, 25), "RGB": ((246, 243, 236), (30, 30, 60))}[mode]
    image = Image.new(mode, size, paper)
    ImageDraw.Draw(image).line(list(zip(x.tolist(), y.tolist())), fill=ink, width=max(3, w // 140), joint="curve")
    return image


def scan_path(folder: Path, kind: str, mpx: float) -> Path:
    return folder / f"scan-{mpx:g}mpx-{kind}.{ {'png': 'png', 'tiff': 'tif', 'jpeg': 'jpg'}[kind.split('-')[0]] }"


def write_scan(kind: str, mpx: float, folder: Path, seed: int) -> Path:
    fmt, mode = kind.split("-")
    image = draw_scan(scan_size(mpx), {"1": "1", "l": "L", "rgb": "RGB"}[mode], seed)
    path = scan_path(folder, kind, mpx)
    if fmt == "png":
        image.save(path, compress_level=1)
    elif fmt == "tiff":
        image.save(path, compression="group4" if mode == "1" else "tiff_lzw")
    else:
        image.save(path, quality=90)
    return path


def run_vectorize(path: Path, out: Path) -> tuple[int, float, float, str]:
    """Exit code, peak RSS (MB), CPU seconds (user + sys) of `onestroke vectorize` in a child.

    The peak is the child's own VmHWM (Linux): ru_maxrss would include this process's
    RSS at the fork, which holds the scan just generated.
    """
    code = ("import os, sys; from fabrication.cli import main\n"
            "try:\n    main()\nexcept SystemExit as e:\n"
            "    hwm = next(l.split()[1] for l in open('/proc/self/status') if l.startswith('VmHWM'))\n"
            "    t = os.times()\n"
            "    print(f'PEAK {hwm} {t.user + t.system}', file=sys.stderr); raise\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-c", code, "vectorize", str(path), "-o", str(out)],
                          capture_output=True, text=True, env=env)
    peak = [l for l in done.stderr.splitlines() if l.startswith("PEAK ")]
    rss_kb, cpu = (float(v) for v in peak[-1].split()[1:]) if peak else (float("nan"), float("nan"))
    message = next((l for l in done.stderr.splitlines() if not l.startswith("PEAK ")), "")
    return done.returncode, rss_kb / 1024.0, cpu, message


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mpx", default="139,300", help="comma-separated sizes in million pixels")
    ap.add_argument("--kinds", default=",".join(KINDS), help=f"comma-separated, of {', '.join(KINDS)}")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--folder", type=Path, default=None, help="where the scans go (default: a temporary folder)")
    ap.add_argument("--keep", action="store_true", help="keep the generated scans (and reuse existing ones)")
    args = ap.parse_args()
    kinds = [k for k in args.kinds.split(",") if k]
    unknown = sorted(set(kinds) - set(KINDS))
    if unknown:
        ap.error(f"unknown kind(s) {', '.join(unknown)}")
    folder = args.folder or Path(tempfile.mkdtemp(prefix="onestroke-scans-"))
    folder.mkdir(parents=True, exist_ok=True)
    print(f"{'scan':34} {'px':>13} {'file MB':>8} {'exit':>4} {'peak RSS MB':>11} {'CPU s':>6}")
    for mpx in (float(m) for m in args.mpx.split(",")):
        for kind in kinds:
            path = scan_path(folder, kind, mpx)
            if not (args.keep and path.exists()):
                path = write_scan(kind, mpx, folder, args.seed)
            with Image.open(path) as scan:
                w, h = scan.size
            code, rss, cpu, message = run_vectorize(path, folder / "out.svg")
            print(f"{path.name:34} {f'{w}x{h}':>13} {path.stat().st_size / 1e6:8.1f} {code:4d} {rss:11.0f} "
                  f"{cpu:6.1f}  {message[:70]}", flush=True)
            if not args.keep:
                path.unlink()
    (folder / "out.svg").unlink(missing_ok=True)
    if not args.keep and args.folder is None:
        folder.rmdir()
    print(f"machine load (1 min): {os.getloadavg()[0]:.1f}; measured {time.strftime('%H:%M UTC', time.gmtime())}")


if __name__ == "__main__":
    main()
