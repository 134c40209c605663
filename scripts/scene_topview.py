#!/usr/bin/env python3
"""Top view of a simulated world: the route (grey), buildings (light grey), plants (green) and
poles (blue), from the scene description sim_sequence writes.

Usage: scripts/scene_topview.py OUT/sequences/00/sim/scene.json TOPVIEW.png [PIXELS_PER_M]

Pure Python (writes the PNG itself); north is up, 40 m of margin around the route.
"""
import json
import math
import struct
import sys
import zlib

from sim_fidelity import write_atomic


def write_png(path, rgb, width, height):
    raw = b"".join(b"\x00" + bytes(rgb[y * width * 3:(y + 1) * width * 3]) for y in range(height))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    write_atomic(path, b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
                 chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def route_points(pieces, step=0.5):
    points = []
    for p in pieces:
        (x, y), h, k, length = p["start"], p["start_heading_rad"], p["curvature"], p["length"]
        n = max(2, int(length / step))
        for i in range(n + 1):
            s = length * i / n
            if k == 0:
                points.append((x + s * math.cos(h), y + s * math.sin(h)))
            else:
                r = 1 / k
                cx, cy, a = x - r * math.sin(h), y + r * math.cos(h), h + s * k
                points.append((cx + r * math.sin(a), cy - r * math.cos(a)))
    return points


def main(argv):
    if len(argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    try:
        with open(argv[0]) as f:
            scene = json.load(f)
        pieces = scene["route"]["pieces"]
        scale = float(argv[2]) if len(argv) == 3 else 1.5
    except (OSError, ValueError, KeyError) as e:
        print(f"scene_topview: {argv[0]}: {e}", file=sys.stderr)
        return 1
    if not scale > 0:
        print("scene_topview: PIXELS_PER_M must be > 0", file=sys.stderr)
        return 2
    points = route_points(pieces)
    x0 = min(p[0] for p in points) - 40
    x1 = max(p[0] for p in points) + 40
    y0 = min(p[1] for p in points) - 40
    y1 = max(p[1] for p in points) + 40
    width, height = int((x1 - x0) * scale), int((y1 - y0) * scale)
    rgb = bytearray([255] * (width * height * 3))

    def put(px, py, colour):
        if 0 <= px < width and 0 <= py < height:
            rgb[(py * width + px) * 3:(py * width + px) * 3 + 3] = bytes(colour)

    def pixel(x, y):
        return int((x - x0) * scale), int((y1 - y) * scale)

    for b in scene.get("buildings", []):
        (cx, cy), yaw, length, depth = b["center"][:2], b["yaw_rad"], b["length"], b["depth"]
        ca, sa = math.cos(yaw), math.sin(yaw)
        reach = int(math.hypot(length, depth) / 2 * scale) + 1
        px, py = pixel(cx, cy)
        for qy in range(py - reach, py + reach + 1):
            for qx in range(px - reach, px + reach + 1):
                dx, dy = qx / scale + x0 - cx, y1 - qy / scale - cy
                if abs(dx * ca + dy * sa) <= length / 2 and abs(-dx * sa + dy * ca) <= depth / 2:
                    put(qx, qy, (150, 150, 150))
    for x, y in points:
        px, py = pixel(x, y)
        for dx in range(-3, 4):
            for dy in range(-3, 4):
                put(px + dx, py + dy, (60, 60, 60))
    for p in scene.get("plants", []):
        px, py = pixel(p["center"][0], p["center"][1])
        r = int(p["radius"] * scale) + 1
        for dx in range(-r, r + 1):
            for dy in range(-r, r + 1):
                if dx * dx + dy * dy <= r * r:
                    put(px + dx, py + dy, (0, 150, 0))
    for p in scene.get("poles", []):
        px, py = pixel(p["base"][0], p["base"][1])
        put(px, py, (0, 0, 255))
        put(px + 1, py, (0, 0, 255))
    write_png(argv[1], rgb, width, height)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
