"""The plot formats the tool writes (matplotlib's savefig, by the file's suffix): one list
for the command line's --plot check and the API's plot functions, in a module light enough
for the CLI's cold start (no numpy)."""

from __future__ import annotations

#: plot formats (matplotlib's savefig, by the file suffix)
PLOT_SUFFIXES = (
    ".png",
    ".svg",
    ".svgz",
    ".pdf",
    ".eps",
    ".ps",
    ".jpg",
    ".jpeg",
    ".tif",
    ".tiff",
    ".webp",
)
