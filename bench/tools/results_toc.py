#!/usr/bin/python3
"""Rewrites the table of contents of bench/RESULTS.md (between its TOC markers) from its `## ` headings.

  /usr/bin/python3 bench/tools/results_toc.py [bench/RESULTS.md]     # --check: exit 1 if it is not current
"""
import re
import sys

BEGIN, END = "<!-- toc -->", "<!-- /toc -->"


def anchor(title, seen):
    """GitHub's heading anchor: lower case, punctuation dropped, spaces to hyphens, -1, -2 for repeats."""
    slug = re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")
    count = seen.get(slug, 0)
    seen[slug] = count + 1
    return slug if count == 0 else f"{slug}-{count}"


def main():
    args = [a for a in sys.argv[1:] if a != "--check"]
    path = args[0] if args else "bench/RESULTS.md"
    text = open(path, encoding="utf-8").read()
    if BEGIN not in text or END not in text:
        sys.exit(f"{path}: no {BEGIN} ... {END} block")
    seen = {}
    entries = []
    in_code = False
    for line in text.splitlines():
        if line.startswith("```"):
            in_code = not in_code
        if in_code:
            continue
        heading = re.match(r"^(#{2,3}) (.*)$", line)
        if heading:
            title = heading.group(2).strip()
            slug = anchor(title, seen)
            if heading.group(1) == "##" and title != "Contents":
                entries.append(f"- [{title}](#{slug})")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    new = head + BEGIN + "\n" + "\n".join(entries) + "\n" + END + tail
    if "--check" in sys.argv:
        sys.exit(0 if new == text else f"{path}: its table of contents is not current; run bench/tools/results_toc.py")
    open(path, "w", encoding="utf-8").write(new)
    print(f"{path}: {len(entries)} sections")


if __name__ == "__main__":
    main()
