#!/usr/bin/env python3
"""The architecture's layers, checked on the sources' #include lines:
the format library (libfiblet/) knows nothing of the CLI, the viewer or the
Python module; those use only public headers (libfiblet/include/fiblet/,
apps/viewer/include/fiblet_viewer/ for the CLI) besides their own files;
no quoted include climbs with ".."; the umbrella header fiblet.hpp includes
every public header; inside the viewer only the technique registry
(techniques/technique_registry.cpp) switches on a drawing style,
transparency mode or engine. Prints each violation; exit 1 if any.

  scripts/check_layers.py [ROOT]
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[1])
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
PUBLIC = {"fiblet": ROOT / "libfiblet/include", "fiblet_viewer": ROOT / "apps/viewer/include"}

# Each component: its sources, the directories its quoted includes may
# resolve in (its own tree first), and the public headers it may use.
COMPONENTS = {
    "libfiblet": (ROOT / "libfiblet", [ROOT / "libfiblet/src", ROOT / "libfiblet/include"], set()),
    "cli": (ROOT / "apps/fiblet", [ROOT / "apps/fiblet"], {"fiblet", "fiblet_viewer"}),
    "viewer": (ROOT / "apps/viewer", [ROOT / "apps/viewer", ROOT / "apps/viewer/include"], {"fiblet"}),
    "python": (ROOT / "python/src", [ROOT / "python/src"], {"fiblet"}),
}


def violations():
    for name, (tree, own, public) in COMPONENTS.items():
        for src in sorted(tree.rglob("*")):
            if src.suffix not in {".cpp", ".hpp", ".inl", ".h"}:
                continue
            for inc in INCLUDE.findall(src.read_text(errors="replace")):
                where = f"{src.relative_to(ROOT)}: #include \"{inc}\""
                if ".." in pathlib.PurePosixPath(inc).parts:
                    yield f"{where}: climbs out with '..'"
                    continue
                if any((d / inc).is_file() for d in own + [src.parent]):
                    continue
                top = inc.split("/", 1)[0]
                if top in public and (PUBLIC[top] / inc).is_file():
                    continue
                yield f"{where}: not {name}'s own file nor a public header it may use"


def umbrella_gaps():
    """The umbrella header fiblet.hpp includes every public header."""
    umbrella = PUBLIC["fiblet"] / "fiblet/fiblet.hpp"
    listed = set(INCLUDE.findall(umbrella.read_text()))
    for h in sorted((PUBLIC["fiblet"] / "fiblet").glob("*.hpp")):
        if h != umbrella and f"fiblet/{h.name}" not in listed:
            yield f"{umbrella.relative_to(ROOT)}: does not include fiblet/{h.name}"


CHOICE = re.compile(r"(==|!=|case)\s*(viewer::)?(DrawStyle|RenderEngine|TransparencyMode)::"
                    r"|(DrawStyle|RenderEngine|TransparencyMode)::\w+\s*(==|!=|\?)")
REGISTRY = ROOT / "apps/viewer/techniques/technique_registry.cpp"


def technique_switches():
    """Comparisons with a style, mode or engine outside the registry."""
    for src in sorted((ROOT / "apps/viewer").rglob("*")):
        if src.suffix not in {".cpp", ".hpp"} or src == REGISTRY:
            continue
        for number, line in enumerate(src.read_text(errors="replace").splitlines(), 1):
            if CHOICE.search(line):
                yield f"{src.relative_to(ROOT)}:{number}: chooses a technique outside {REGISTRY.relative_to(ROOT)}"


found = list(violations()) + list(umbrella_gaps()) + list(technique_switches())
for v in found:
    print(v)
print(f"check_layers: {len(found)} violation(s)")
sys.exit(1 if found else 0)
