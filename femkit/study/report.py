"""Report writing: ``report.md``, a self-contained ``report.html``, CSV and JSON data.

A report is a list of blocks (headings, paragraphs, tables, figures) rendered twice:
Markdown with relative links to the PNGs in ``figures/``, and HTML with every PNG embedded
as a base64 ``data:image/png`` URI (the file can be mailed on its own).

Writes are atomic at the directory level: :func:`staged_output` hands out a fresh temporary
directory beside the target; only when the whole study succeeded is it renamed into place
(the previous report, if any, is moved aside first and then deleted). A crashed or interrupted
study leaves the previous report untouched and no half-written one.

>>> r = Report("demo")
>>> r.table(["a", "b"], [[1, 2.5e-3]])
>>> print(r.to_markdown().splitlines()[-1])
| 1 | 0.0025 |
"""

from __future__ import annotations

import base64
import html
import math
import os
from typing import Any, Sequence

import numpy as np

from ..io.writers import to_jsonable, write_csv, write_json  # noqa: F401  (the one writer of each format)

__all__ = ["Report", "staged_output", "write_csv", "write_json", "to_jsonable", "fmt"]


def fmt(v: Any) -> str:
    """Table cell text: floats with 4 significant digits, bools as yes/no, None as '-'."""
    if v is None:
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if math.isnan(v):
            return "-"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:.4g}"
    return str(v)


class Report:
    """Blocks of a study report, rendered to Markdown and HTML."""

    def __init__(self, title: str):
        self.title = title
        self.blocks: list[tuple[str, Any]] = []

    def heading(self, text: str, level: int = 2) -> None:
        self.blocks.append(("heading", (level, text)))

    def paragraph(self, text: str) -> None:
        self.blocks.append(("paragraph", text))

    def table(self, columns: Sequence[str], rows: Sequence[Sequence[Any]], caption: str | None = None) -> None:
        self.blocks.append(("table", (list(columns), [list(r) for r in rows], caption)))

    def figure(self, relpath: str, caption: str) -> None:
        self.blocks.append(("figure", (relpath, caption)))

    @property
    def figures(self) -> list[str]:
        return [b[1][0] for b in self.blocks if b[0] == "figure"]

    def to_markdown(self) -> str:
        out = [f"# {self.title}", ""]
        for kind, data in self.blocks:
            if kind == "heading":
                out += [f"{'#' * data[0]} {data[1]}", ""]
            elif kind == "paragraph":
                out += [data, ""]
            elif kind == "table":
                cols, rows, caption = data
                if caption:
                    out += [f"*{caption}*", ""]
                out.append("| " + " | ".join(cols) + " |")
                out.append("|" + "|".join("---" for _ in cols) + "|")
                out += ["| " + " | ".join(fmt(v).replace("|", "\\|") for v in r) + " |" for r in rows]
                out.append("")
            elif kind == "figure":
                rel, caption = data
                out += [f"![{caption}]({rel})", "", f"*{caption}*", ""]
        return "\n".join(out).rstrip() + "\n"

    def to_html(self, base_dir) -> str:
        """HTML with each figure read from ``base_dir/relpath`` and embedded as a data URI."""
        e = html.escape
        out = ["<!DOCTYPE html>", "<html><head><meta charset='utf-8'>", f"<title>{e(self.title)}</title>",
               "<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em}"
               "table{border-collapse:collapse;margin:1em 0;font-size:0.9em}"
               "td,th{border:1px solid #bbb;padding:2px 8px;text-align:right}th{background:#eee}"
               "td:first-child,th:first-child{text-align:left}img{max-width:100%}"
               "figcaption{font-style:italic;color:#444}</style>",
               "</head><body>", f"<h1>{e(self.title)}</h1>"]
        for kind, data in self.blocks:
            if kind == "heading":
                out.append(f"<h{data[0]}>{e(data[1])}</h{data[0]}>")
            elif kind == "paragraph":
                out.append(f"<p>{e(data)}</p>")
            elif kind == "table":
                cols, rows, caption = data
                out.append("<table>")
                if caption:
                    out.append(f"<caption>{e(caption)}</caption>")
                out.append("<tr>" + "".join(f"<th>{e(c)}</th>" for c in cols) + "</tr>")
                for r in rows:
                    out.append("<tr>" + "".join(f"<td>{e(fmt(v))}</td>" for v in r) + "</tr>")
                out.append("</table>")
            elif kind == "figure":
                rel, caption = data
                with open(os.path.join(base_dir, rel), "rb") as fh:
                    b64 = base64.b64encode(fh.read()).decode("ascii")
                out.append(f"<figure><img alt='{e(caption)}' src='data:image/png;base64,{b64}'>"
                           f"<figcaption>{e(caption)}</figcaption></figure>")
        out.append("</body></html>")
        return "\n".join(out) + "\n"

    def write(self, directory) -> None:
        """Write ``report.md`` and ``report.html`` into ``directory`` (figures must already be there)."""
        directory = os.fspath(directory)
        with open(os.path.join(directory, "report.md"), "w", encoding="utf-8") as fh:
            fh.write(self.to_markdown())
        with open(os.path.join(directory, "report.html"), "w", encoding="utf-8") as fh:
            fh.write(self.to_html(directory))


def staged_output(output_dir):
    """Context manager yielding a temporary directory that replaces ``output_dir`` on success.

    The study-side name of :func:`femkit.io.atomic.atomic_directory`: on an exception the
    temporary directory is removed and ``output_dir`` (an earlier report) is untouched.
    """
    from ..io.atomic import EARLIER_REPORT, atomic_directory

    return atomic_directory(output_dir, EARLIER_REPORT)
