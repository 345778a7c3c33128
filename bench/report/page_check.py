#!/usr/bin/env python3
"""Checks a report opened in headless Chromium (bench/report/check.sh).

Usage: page_check.py DOM.html SCREENSHOT.png

Fails (exit 1) unless the viewer set its drawn marker (<body data-drawn="1">),
the page's error element (<pre id="errors">) is empty, and the screenshot's
canvas area is not blank: enough pixels differ from the canvas background and
enough distinct colours are drawn. Standard library only (zlib decodes PNG).
"""
import html
import re
import struct
import sys
import zlib

CANVAS_BACKGROUND = (244, 245, 247)  # #f4f5f7 in report.css
MIN_DRAWN_SHARE = 0.02  # share of canvas pixels that must differ from the background
MIN_COLOURS = 8  # distinct colours in the canvas area (shaded part + toolpath)


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG")
    pos, idat, width = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                raise SystemExit(f"{path}: unsupported PNG (depth {depth}, colour {colour}, interlace {interlace})")
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pr) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, channels, rows


def main():
    dom_path, png_path = sys.argv[1], sys.argv[2]
    dom = open(dom_path, encoding="utf-8", errors="replace").read()
    failures = []
    body = re.search(r"<body[^>]*>", dom)
    if not body or 'data-drawn="1"' not in body.group(0):
        failures.append("the viewer did not set its drawn marker (<body data-drawn=\"1\">)")
    errors = re.search(r'<pre id="errors">(.*?)</pre>', dom, re.S)
    if errors is None:
        failures.append("no <pre id=\"errors\"> element in the page")
    elif errors.group(1).strip():
        failures.append("the page reported errors: " + html.unescape(errors.group(1).strip()))
    width, height, channels, rows = read_png(png_path)
    # The canvas area: the pixels whose colour is the canvas background, and
    # everything between the first and last such rows (the canvas spans the page width).
    bg_rows = [y for y, r in enumerate(rows) if r.count(bytes(CANVAS_BACKGROUND)) > width // 4]
    if not bg_rows:
        failures.append("no canvas background in the screenshot: the canvas is not visible")
    else:
        y0, y1 = bg_rows[0], bg_rows[-1]
        drawn, colours, total = 0, set(), 0
        for y in range(y0, y1 + 1):
            r = rows[y]
            for x in range(0, width):
                px = tuple(r[x * channels:x * channels + 3])
                total += 1
                colours.add(px)
                if max(abs(px[k] - CANVAS_BACKGROUND[k]) for k in range(3)) > 8:
                    drawn += 1
        share = drawn / max(1, total)
        print(f"{png_path}: canvas rows {y0}..{y1}, {drawn} of {total} pixels drawn ({100 * share:.1f} %), "
              f"{len(colours)} colours")
        if share < MIN_DRAWN_SHARE:
            failures.append(f"the canvas is blank: {100 * share:.2f} % of its pixels drawn (< {100 * MIN_DRAWN_SHARE} %)")
        if len(colours) < MIN_COLOURS:
            failures.append(f"the canvas has {len(colours)} colours (< {MIN_COLOURS})")
    for f in failures:
        print(f"{dom_path}: {f}", file=sys.stderr)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
