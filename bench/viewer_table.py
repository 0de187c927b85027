#!/usr/bin/env python3
"""The viewer benchmark's table (scripts/bench_viewer.sh): reads its rows
(technique TAB render options TAB `fiblet render --bench --json` output) and
writes one JSON file and one Markdown table of frame times per technique,
overview and close-up, with culling + level of detail (the viewer's
default) and without."""
import argparse
import datetime
import json
import sys


def read_rows(path):
    rows = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            parts = line.rstrip("\n").split("\t", 2)
            if len(parts) != 3:
                sys.exit(f"{path}:{n}: expected technique, options and JSON separated by tabs")
            rows.append({"technique": parts[0], "options": parts[1], "result": json.loads(parts[2])})
    if not rows:
        sys.exit(f"{path}: no rows")
    return rows


def case(result, view, selection):
    for c in result["cases"]:
        if c["view"] == view and c["culling_and_lod"] == selection:
            return c
    return None


def markdown(rows, command):
    first = rows[0]["result"]
    lines = [
        f"Device: {first['device']}; timing: {first['timing']}.",
        f"File: `{first['file']}` ({first['fibers']:,} fibers, {first['blocks']:,} blocks), "
        f"{first['width']}x{first['height']}, median of {first['frames']} frame(s) after a warm-up one; "
        f"{datetime.date.today().isoformat()}.",
        f"Command: `{command}`.",
        "",
    ]
    if first.get("decode_all_scan_ms") is not None:
        lines += [f"Decoding every block: scan {first['decode_all_scan_ms']:.2f} ms, "
                  f"sequential {first['decode_all_sequential_ms']:.2f} ms.", ""]
    lines += [
        "| technique | overview ms (culling + LoD) | overview ms (all blocks) | close-up ms (culling + LoD) | "
        "close-up ms (all blocks) | segments, overview |",
        "|---|---|---|---|---|---|",
    ]
    for row in rows:
        r = row["result"]
        cells = [row["technique"]]
        for view in ("overview", "close-up"):
            for selection in (True, False):
                c = case(r, view, selection)
                cells.append(f"{c['frame_ms']:.2f}" if c else "–")
        on = case(r, "overview", True)
        cells.append(f"{on['gpu']['segments']:,}" if on else "–")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("rows")
    p.add_argument("--json", required=True)
    p.add_argument("--markdown", required=True)
    p.add_argument("--command", default="scripts/bench_viewer.sh")
    a = p.parse_args()
    rows = read_rows(a.rows)
    with open(a.json, "w") as f:
        json.dump({"command": a.command, "rows": rows}, f, indent=1)
        f.write("\n")
    with open(a.markdown, "w") as f:
        f.write(markdown(rows, a.command))


if __name__ == "__main__":
    main()
