#!/usr/bin/env python3
"""Writes fixtures/synthetic/archipelago-<n>.geojson: a 200 × 120 sea (box) with n small
islands (irregular heptagons, radius 0.35–0.9) placed along five curved chains, at least 1.2
apart (edge to edge ≥ 0.3 for the largest pairs). Deterministic (seeded). The test case for
the requirement that a sea with hundreds of small islands be meshed, not rejected.

    python3 scripts/make_archipelago.py 500 > fixtures/synthetic/archipelago-500.geojson
"""
import json, math, random, sys

def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 500
    rnd = random.Random(22)
    W, H = 200.0, 120.0
    centres = []
    chains = 5
    tries = 0
    while len(centres) < n and tries < 200000:
        tries += 1
        c = len(centres) % chains
        t = rnd.random()
        x = 10 + t * (W - 20)
        y = (c + 0.5) * H / chains + 6.0 * math.sin(2 * math.pi * (t * (1.5 + 0.3 * c)) + c) + rnd.gauss(0, 2.5)
        if not (4 < y < H - 4):
            continue
        if all((x - a) ** 2 + (y - b) ** 2 >= 2.4 ** 2 for a, b, _ in centres):
            centres.append((x, y, 0.35 + 0.55 * rnd.random()))
    holes = []
    for x, y, r in centres:
        k = 7
        ring = []
        for i in range(k):
            a = 2 * math.pi * i / k + rnd.random() * 0.3
            rr = r * (0.75 + 0.25 * rnd.random())
            ring.append([round(x + rr * math.cos(a), 6), round(y + rr * math.sin(a), 6)])
        ring.reverse()  # clockwise hole
        ring.append(ring[0])
        holes.append(ring)
    outer = [[0, 0], [W, 0], [W, H], [0, H], [0, 0]]
    doc = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"name": f"archipelago-{len(centres)}", "source": "scripts/make_archipelago.py (synthetic, public domain)"}, "geometry": {"type": "Polygon", "coordinates": [outer] + holes}}]}
    json.dump(doc, sys.stdout)

main()
