"""Times OpenCV on the frames and windows `cargo bench -p harvey-vision --bench kernels` used,
single thread, and writes the Harvey / OpenCV table into docs/benchmarks.md: one table per
instruction-set path the kernels bench ran (`HARVEY_SIMD`), each headed by the CPU model, its
SIMD features and the path, between `<!-- vision-opencv:PATH:start -->` and `...:end -->`.

OpenCV has no Moravec operator, no Burns line finder and no reflectance-normalised correlation;
each row names the nearest OpenCV routine timed in its place: TM_CCORR_NORMED template matching,
cornerMinEigenVal with the same 5x5 block plus a dilate-based local-maximum test, the LSD line
segment detector, and LUT + connectedComponentsWithStats per class.
"""

import statistics
import sys
import time
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT / "target" / "vision-bench"
DOC = ROOT / "docs" / "benchmarks.md"


def markers(path):
    return f"<!-- vision-opencv:{path}:start -->", f"<!-- vision-opencv:{path}:end -->"


def timed(f, budget=0.3):
    f()
    t0 = time.perf_counter()
    f()
    once = max(time.perf_counter() - t0, 1e-7)
    reps = int(min(max(budget / once, 5), 20000))
    samples = []
    for _ in range(reps):
        t = time.perf_counter()
        f()
        samples.append((time.perf_counter() - t) * 1e6)
    return statistics.median(samples)


def rect(text):
    x0, y0, x1, y1 = (int(v) for v in text.split(","))
    return x0, y0, x1, y1


def opencv_case(kernel, img, win, tmpl):
    x0, y0, x1, y1 = win
    sub = np.ascontiguousarray(img[y0:y1, x0:x1])
    if kernel.startswith("normalised correlation") or kernel.startswith("coarse-to-fine"):
        tx0, ty0, tx1, ty1 = tmpl
        t = np.ascontiguousarray(img[ty0:ty1, tx0:tx1])
        return "matchTemplate TM_CCORR_NORMED + minMaxLoc", lambda: cv2.minMaxLoc(
            cv2.matchTemplate(sub, t, cv2.TM_CCORR_NORMED))
    if kernel.startswith("Moravec"):
        kernel7 = np.ones((7, 7), np.uint8)

        def corners():
            e = cv2.cornerMinEigenVal(sub, 5)
            peaks = (e == cv2.dilate(e, kernel7)) & (e > 1e-3)
            return np.count_nonzero(peaks)
        return "cornerMinEigenVal 5x5 + dilate maxima", corners
    if kernel.startswith("fast line finder"):
        lsd = cv2.createLineSegmentDetector()
        return "LSD line segment detector", lambda: lsd.detect(sub)
    if kernel.startswith("fast region segmenter"):
        lut = np.zeros(256, np.uint8)
        lut[0:71], lut[71:171], lut[171:256] = 1, 2, 3

        def regions():
            classes = cv2.LUT(sub, lut)
            return [cv2.connectedComponentsWithStats((classes == c).astype(np.uint8), connectivity=8)
                    for c in (1, 2, 3)]
        return "LUT + connectedComponentsWithStats per class", regions
    if kernel.startswith("activity"):
        frames = [sub, np.ascontiguousarray(np.roll(sub, -1, axis=1))]

        def motion():
            acc = np.zeros(sub.shape, np.float32)
            for a, b in zip(frames + frames, (frames + frames)[1:4]):
                cv2.accumulate(cv2.absdiff(a, b), acc)
            return cv2.moments(acc)
        return "absdiff + accumulate (3 pairs) + moments", motion
    if kernel.startswith("phototropic"):
        def bright():
            _, peak, _, _ = cv2.minMaxLoc(sub)
            _, mask = cv2.threshold(sub, peak - 21, 255, cv2.THRESH_BINARY)
            return cv2.connectedComponentsWithStats(mask, connectivity=8)
        return "minMaxLoc + threshold + connectedComponentsWithStats", bright
    if kernel.startswith(NO_COUNTERPART):
        return None
    raise ValueError(kernel)


# Kernels on frame pairs (stereo, depth from motion: the bench exports one frame) or on line
# lists (the dock Hough, path grouping: the line finder's row already compares LSD), or on two
# stops of a stereo pair (visual odometry).
NO_COUNTERPART = ("stereo", "depth from motion", "constrained Hough", "path following", "visual odometry")


def main():
    cv2.setNumThreads(1)
    text = (BENCH / "harvey.tsv").read_text().splitlines()
    meta = dict(l[2:].split("\t", 1) for l in text if l.startswith("# "))
    rows = [l.split("\t") for l in text if not l.startswith("# ")][1:]
    path = meta.get("path", "unknown")
    print(f"CPU: {meta.get('cpu', 'unknown')}")
    print(f"SIMD features: {meta.get('features', 'unknown')}")
    print(f"Harvey path: {path}")
    frames = {}
    lines = ["| kernel | image | scope | path | Harvey µs | OpenCV µs | OpenCV routine | OpenCV / Harvey |",
             "|---|---|---|---|---:|---:|---|---:|"]
    for kernel, size, scope, win, tmpl, harvey_us, _ref, row_path in rows:
        img = frames.setdefault(size, cv2.imread(str(BENCH / f"frame_{size}.pgm"), cv2.IMREAD_GRAYSCALE))
        if img is None:
            sys.exit(f"cannot read {BENCH / f'frame_{size}.pgm'}: run the kernels bench first")
        case = opencv_case(kernel, img, rect(win), rect(tmpl))
        if case is None:
            continue
        name, f = case
        us = timed(f)
        lines.append(f"| {kernel} | {size} | {scope} | {row_path} | {float(harvey_us):.1f} | {us:.1f} | {name} | "
                     f"{us / float(harvey_us):.2f}x |")
    table = "\n".join(lines)
    print(table)
    text = DOC.read_text()
    start, end = markers(path)
    block = (f"{start}\nCPU: {meta.get('cpu', 'unknown')}; SIMD features: {meta.get('features', 'unknown')}; "
             f"Harvey path: {path}. OpenCV {cv2.__version__}, `cv2.setNumThreads(1)`, same frames and windows "
             f"(no rows for {', '.join(NO_COUNTERPART)}: no counterpart on one frame):\n\n{table}\n{end}")
    if start in text and end in text:
        text = text[: text.index(start)] + block + text[text.index(end) + len(end):]
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    DOC.write_text(text)
    print(f"written into {DOC.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
