"""The command line's help, fitted to :data:`HELP_WIDTH` columns: ``neurocur --help`` and every subcommand's,
the fit layer's included, keep their examples' layout and wrap what is too long."""

from __future__ import annotations

import argparse
import re
import shutil
import textwrap

__all__ = ["HELP_WIDTH", "HelpFormatter"]

#: the widest a help text gets, on a terminal however wide
HELP_WIDTH = 100


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Help that fits :data:`HELP_WIDTH` columns, or the terminal when it is narrower.

    Descriptions and epilogs keep their lines (the examples' layout) where they fit. A paragraph
    of prose (unindented lines) with a line too long is filled again; a too long indented line
    is wrapped at spaces: an example command (``neurocur ...``) into shell continuation lines
    ending in ``\\``, a line with a column (an example and its comment, two spaces or more apart)
    under that column, any other line under its own indentation.

    Parameters
    ----------
    prog : str
        The program's name, as argparse passes it.
    **kwargs
        argparse's formatter options; ``width`` defaults to the narrower of `HELP_WIDTH` and the
        terminal, less two columns.
    """

    def __init__(self, prog: str, **kwargs) -> None:
        kwargs.setdefault("width", min(shutil.get_terminal_size().columns, HELP_WIDTH) - 2)
        super().__init__(prog, **kwargs)

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        lines = [indent + line for line in text.splitlines()]
        out: list[str] = []
        while lines:
            line = lines.pop(0)
            if not line[:1].isspace() and line.strip():  # prose: the paragraph of the following unindented lines
                paragraph = [line]
                while lines and lines[0].strip() and not lines[0][:1].isspace():
                    paragraph.append(lines.pop(0))
                fits = max(len(part) for part in paragraph) <= width
                out += paragraph if fits else textwrap.wrap(" ".join(paragraph), width, break_long_words=False,
                                                            break_on_hyphens=False)
            else:
                out += _wrap(line, width)
        return "".join(line + "\n" for line in out)


def _wrap(line: str, width: int) -> list[str]:
    """The indented ``line`` wrapped to ``width`` columns as `HelpFormatter` says."""
    if len(line) <= width:
        return [line]
    lead = line[: len(line) - len(line.lstrip())]
    column = re.match(r"\s*\S.*?\S {2,}(?=\S)", line)
    if line.lstrip().startswith("neurocur ") and column is None:
        parts = textwrap.wrap(line, width - 2, subsequent_indent=lead + "    ", break_long_words=False,
                              break_on_hyphens=False)
        return [part + " \\" for part in parts[:-1]] + parts[-1:]
    for hang in ([" " * column.end()] if column is not None else []) + [lead]:  # a word too long for the column
        parts = textwrap.wrap(line, width, subsequent_indent=hang, break_long_words=False, break_on_hyphens=False)
        if max(len(part) for part in parts) <= width:
            break
    return parts
