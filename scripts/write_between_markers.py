#!/usr/bin/env python3
"""Puts generated text into a document between its markers: the lines that start with
`<!-- NAME:begin` and `<!-- NAME:end -->` (scripts/accuracy.sh, bench/accuracy_table.py).

    scripts/write_between_markers.py DOC NAME FILE   # the text of FILE into DOC
"""
import sys


def write_between_markers(doc, name, text):
    """Replaces what lies between DOC's NAME markers by `text`; exits naming DOC without them."""
    content = open(doc).read()
    begin, end = f"<!-- {name}:begin", f"<!-- {name}:end -->"
    i, j = content.find(begin), content.find(end)
    if i < 0 or j < i:
        sys.exit(f"{doc} has no {name} markers")
    i = content.index("\n", i) + 1
    with open(doc, "w") as f:
        f.write(content[:i] + "\n" + text.rstrip("\n") + "\n\n" + content[j:])


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    write_between_markers(sys.argv[1], sys.argv[2], open(sys.argv[3]).read())
