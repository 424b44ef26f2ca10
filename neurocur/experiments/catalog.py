"""The shipped experiments, invariance demonstrations and circuits, one line each (``neurocur list``)."""

from __future__ import annotations

from neurocur.tables import load_toml, shipped_files

__all__ = ["catalog", "format_catalog"]

#: kind -> the heading of its files and how the command line uses one
USES = {"experiment": ("experiments", "neurocur run NAME"),
        "invariance": ("invariance demonstrations", "neurocur invariance NAME"),
        "circuit": ("circuits", 'circuit = "NAME" in an experiment file')}
#: the longest description shown
WIDTH = 100


def catalog() -> dict[str, dict[str, str]]:
    """kind -> {name: the file's own description on one line} for every shipped file."""
    return {kind: {name: _one_line(load_toml(path).get("description", "")) for name, path in shipped_files(kind).items()}
            for kind in USES}


def format_catalog() -> str:
    """The catalogue as text: a heading per kind, then one line per name."""
    lines = []
    for kind, names in catalog().items():
        heading, use = USES[kind]
        lines.append(f"{heading} ({use}):")
        width = max(map(len, names), default=0)
        lines += [f"  {name:<{width}}  {text}".rstrip() for name, text in names.items()]
    return "\n".join(lines)


def _one_line(text) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= WIDTH else text[: WIDTH - 3].rstrip() + "..."
