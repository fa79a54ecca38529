#!/usr/bin/env python3
"""Independent check of a Gmsh MSH file with Gmsh's own Python API (https://pypi.org/project/gmsh/).

Opens FILE with gmsh (not with unamalla's reader) and compares it with the expected counts:
number of nodes, number of elements of each type, physical groups (dimension and name) with
the number of elements in each, and optionally that Gmsh's minSICN quality (signed inverse
condition number; > 0 means a valid, non-inverted element) is > 0 for every element of the
given dimension. Prints a JSON summary on stdout; on any mismatch prints the problems on stderr
and exits with status 1 (status 2 for usage errors or when gmsh is missing or cannot open FILE).

Example:
    python3 scripts/check_msh_gmsh.py mesh.msh --nodes 20 --elements quad=12 \
        --elements line=14 --group 2:domain=12 --group 1:outer=14 --min-sicn-positive 2
"""

import argparse
import json
import math
import sys

# Gmsh element type numbers.
TYPES = {"line": 1, "triangle": 2, "quad": 3, "tetrahedron": 4, "hexahedron": 5, "point": 15}


def parse_kv(text, what):
    key, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"{what}: expected KEY=COUNT, got {text!r}")
    return key, int(value)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", help="MSH file to check")
    ap.add_argument("--nodes", type=int, required=True, help="expected number of nodes")
    ap.add_argument(
        "--elements",
        action="append",
        default=[],
        metavar="TYPE=COUNT",
        help=f"expected number of elements of a type ({', '.join(TYPES)}); repeatable; "
        "types not listed must be absent",
    )
    ap.add_argument(
        "--group",
        action="append",
        default=[],
        metavar="DIM:NAME=COUNT",
        help="a physical group that must exist with this dimension, name and element count "
        "(repeatable); groups not listed must be absent",
    )
    ap.add_argument(
        "--min-sicn-positive",
        type=int,
        metavar="DIM",
        help="require Gmsh's minSICN quality > 0 for every element of this dimension",
    )
    args = ap.parse_args()
    try:
        expected_types = {TYPES[k]: v for k, v in (parse_kv(e, "--elements") for e in args.elements)}
        expected_groups = {}
        for g in args.group:
            dim, _, rest = g.partition(":")
            name, count = parse_kv(rest, "--group")
            expected_groups[(int(dim), name)] = count
    except (KeyError, ValueError, argparse.ArgumentTypeError) as e:
        print(f"error: bad argument: {e}", file=sys.stderr)
        return 2

    try:
        import gmsh  # noqa: PLC0415 (imported late so that --help works without gmsh)
    except ImportError:
        print("error: gmsh is not installed (pip install gmsh)", file=sys.stderr)
        return 2

    gmsh.initialize(["-noenv"], readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        try:
            gmsh.open(args.file)
        except Exception as e:  # gmsh raises a plain Exception with its log message
            print(f"error: gmsh could not open {args.file}: {e}", file=sys.stderr)
            return 2
        problems = []

        node_tags, coords, _ = gmsh.model.mesh.getNodes()
        n_nodes = len(node_tags)
        if n_nodes != args.nodes:
            problems.append(f"nodes: expected {args.nodes}, gmsh read {n_nodes}")
        if not all(math.isfinite(c) for c in coords):
            problems.append("nodes: non-finite coordinate")

        types, elem_tags, _ = gmsh.model.mesh.getElements()
        counts = {int(t): len(tags) for t, tags in zip(types, elem_tags)}
        for t, c in expected_types.items():
            if counts.get(t, 0) != c:
                problems.append(f"elements of type {t}: expected {c}, gmsh read {counts.get(t, 0)}")
        for t, c in counts.items():
            if t not in expected_types and c:
                problems.append(f"elements of type {t}: {c} unexpected")

        groups = {}
        for dim, tag in gmsh.model.getPhysicalGroups():
            name = gmsh.model.getPhysicalName(dim, tag)
            n = 0
            for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                _, etags, _ = gmsh.model.mesh.getElements(dim, ent)
                n += sum(len(x) for x in etags)
            groups[f"{dim}:{name}"] = n
            key = (dim, name)
            if key not in expected_groups:
                problems.append(f"physical group {dim}:{name!r}: unexpected")
            elif expected_groups[key] != n:
                problems.append(
                    f"physical group {dim}:{name!r}: expected {expected_groups[key]} elements, "
                    f"gmsh found {n}"
                )
        for dim, name in expected_groups:
            if f"{dim}:{name}" not in groups:
                problems.append(f"physical group {dim}:{name!r}: missing (gmsh found {sorted(groups)})")

        sicn = None
        if args.min_sicn_positive is not None:
            d = args.min_sicn_positive
            _, tags_d, _ = gmsh.model.mesh.getElements(d)
            tags = [int(t) for block in tags_d for t in block]
            if not tags:
                problems.append(f"minSICN: no elements of dimension {d}")
            else:
                q = gmsh.model.mesh.getElementQualities(tags, "minSICN")
                sicn = {"min": float(min(q)), "max": float(max(q)), "count": len(q)}
                bad = [t for t, v in zip(tags, q) if not v > 0.0]
                if bad:
                    problems.append(
                        f"minSICN: {len(bad)} element(s) of dimension {d} with minSICN <= 0, "
                        f"first tag {bad[0]}"
                    )

        summary = {
            "file": args.file,
            "gmsh_version": gmsh.__version__,
            "nodes": n_nodes,
            "element_counts": {str(k): v for k, v in sorted(counts.items())},
            "physical_groups": groups,
            "min_sicn": sicn,
            "ok": not problems,
            "problems": problems,
        }
        print(json.dumps(summary, indent=2, sort_keys=True))
        for p in problems:
            print(f"mismatch: {p}", file=sys.stderr)
        return 1 if problems else 0
    finally:
        gmsh.finalize()


if __name__ == "__main__":
    sys.exit(main())
