#!/usr/bin/env python3
"""docs/usage.md's option reference, generated from the binary's own option registry (issue 71).

Under each command's heading (`## mufric train`, `## mufric dataset plan`, ...) docs/usage.md holds
that command's `--help`, as CLI11 prints it from the options the code declares, between markers:

    <!-- BEGIN generated: mufric train --help -->
    ```text
    ...
    ```
    <!-- END generated -->

and its table of contents holds the list of commands between `<!-- BEGIN generated: commands -->`
and `<!-- END generated -->`. The prose around the blocks is written by hand and never touched.

Usage:
  usage_reference.py MUFRIC_BINARY docs/usage.md           check; exit 1 listing every command whose
                                                           block differs or is missing, and every
                                                           heading for a command the binary no longer has
  usage_reference.py MUFRIC_BINARY docs/usage.md --write   rewrite every generated block from the binary

--write also adds what is missing: a block under a command's heading that has none, and a heading
with its block for a command that has no heading at all (above the `<!-- END commands` marker that
closes the commands part, or at the end of the file without one), so that a new command cannot be
forgotten; write its prose by hand afterwards. A heading or block for a command the binary no longer
has is reported by both modes and left for a person to remove (its prose may belong elsewhere).
The commands are found by walking `mufric --help`'s "Subcommands:" list, then each one's, recursively.
Exit codes: 0 current (or rewritten), 1 drift (or, with --write, a stale heading left), 2 misuse or a
binary that fails. python3's standard library only.
"""
import difflib
import os
import re
import subprocess
import sys

BEGIN = "<!-- BEGIN generated: {} -->"
END = "<!-- END generated -->"
TOC_KEY = "commands"
# The scene keys' reference: `mufric micro keys` prints it (Markdown, from the scene reader itself),
# kept under "## Scene keys" after "## Scenes".
SCENE_KEYS_KEY = "mufric micro keys"
SCENE_KEYS_SECTION = "## Scene keys\n\nEvery key a scene file can set, generated from the scene reader itself (`mufric micro keys`):\n" \
    "its type (a quantity's kind takes a value with its unit, `\"400MPa\"`), the value an absent key takes and its\n" \
    "range or words. Keys that only some interface laws read are named with those laws. The readings are the\n" \
    "default scene's (dry, lubricated and under seed 000's protocol, synthetic surfaces): a surface given by a\n" \
    "profile file instead, `geometry.tool_surface.csv` or `geometry.chip_surface.csv` (columns `x`, `height` with\n" \
    "units), is described under Scenes above.\n\n"
END_OF_COMMANDS = "<!-- END commands"
BLOCK_RE = re.compile(r"^<!-- BEGIN generated: (.+?) -->\n(.*?)^<!-- END generated -->\n?", re.M | re.S)
HEADING_RE = re.compile(r"^## (mufric(?: [A-Za-z0-9_-]+)*)[ \t]*$", re.M)

# What the binary prints that depends on the machine it runs on rather than on the code. Each help
# text was compared run from another directory, under `taskset -c 0`, OMP_NUM_THREADS=3, another HOME
# and MUFRIC_MODELS_DIR: no help text prints a core or thread count (the thread options say "0: the
# cores this process may use" and "cores / jobs" in words), and the column layout is CLI11's fixed
# one, not the terminal's width. Two defaults are paths of the machine and are replaced here:
NORMALISATIONS = [
    # `serve --models` names the shipped models' directory it found: where libmufric is installed,
    # MUFRIC_MODELS_DIR, or "none found" in a build tree.
    (re.compile(r"\(default: the shipped models, [^)\n]*\)"),
     "(default: the shipped models, PREFIX/share/mufric/models)"),
    # `learn run --slurm-submit` defaults to the source tree's deploy/slurm/submit-dataset.sh, an
    # absolute path compiled in (app/CMakeLists.txt, MUFRIC_SLURM_SUBMIT).
    (re.compile(r"=\S*(/deploy/slurm/submit-dataset\.sh)"), r"=SOURCE_DIR\1"),
]
# Besides these: CLI11 prints argv[0] on every usage line ("Usage: ./build/app/mufric train ..."):
# it becomes "mufric"; trailing spaces and trailing blank lines are dropped.


def fail(message):
    print(f"usage_reference.py: error: {message}", file=sys.stderr)
    sys.exit(2)


def raw_help(binary, path, flag="--help"):
    command = [binary, *path] + ([flag] if flag else [])
    try:
        done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as error:
        fail(f"{' '.join(command)}: {error}")
    if done.returncode != 0:
        fail(f"{' '.join(command)} exited {done.returncode}: {done.stderr.decode(errors='replace').strip()}")
    return done.stdout.decode("utf-8")


def normalise(text, binary):
    lines = []
    for line in text.splitlines():
        if line.startswith("Usage: " + binary):
            line = "Usage: mufric" + line[len("Usage: " + binary):]
        lines.append(line.rstrip())
    text = "\n".join(lines).strip("\n")
    for pattern, replacement in NORMALISATIONS:
        text = pattern.sub(replacement, text)
    return text


def subcommands(text):
    """(name, description) of each entry in a help text's "Subcommands:" list, in its order."""
    entries, inside = [], False
    for line in text.splitlines():
        if line == "Subcommands:":
            inside = True
        elif inside and not line.strip():
            break
        elif inside:
            entry = re.match(r"^  (\S+)(?:\s+(.*))?$", line)
            if entry and not line.startswith("   "):
                entries.append([entry.group(1), (entry.group(2) or "").strip()])
            elif entries:  # a description wrapped onto its own line(s)
                entries[-1][1] = (entries[-1][1] + " " + line.strip()).strip()
    return entries


def walk(binary):
    """Every command, depth first in the binary's order: (path, normalised help, description)."""
    found = []

    def visit(path, description):
        text = raw_help(binary, path)
        found.append((tuple(path), normalise(text, binary), description))
        for name, what in subcommands(text):
            visit([*path, name], what)

    visit([], "")
    return found


def key_of(path):
    return " ".join(["mufric", *path, "--help"])


def title_of(path):
    return " ".join(["mufric", *path])


def anchor_of(path):
    # GitHub's heading anchors: lower case, spaces to hyphens (command names have no other punctuation).
    return "#" + title_of(path).lower().replace(" ", "-")


def block_body(help_text):
    fence = "```"
    while fence in help_text:
        fence += "`"
    return f"{fence}text\n{help_text}\n{fence}\n"


def markdown_text(text):
    return re.sub(r"([*\\<\[\]])", r"\\\1", text)


def toc_body(commands):
    """The commands part of the table of contents: top-level commands with what they do, groups with
    their subcommands' links."""
    children = {}
    for path, _, _ in commands:
        if path:
            children.setdefault(path[:-1], []).append(path)

    def links(parent):
        parts = []
        for path in children.get(parent, []):
            part = f"[`{path[-1]}`]({anchor_of(path)})"
            if path in children:
                part += " (" + links(path) + ")"
            parts.append(part)
        return ", ".join(parts)

    lines = [f"- [`mufric`]({anchor_of(())}): the commands, `--help`, `--version`, errors and exit codes"]
    for path, _, description in commands:
        if len(path) != 1:
            continue
        line = f"- [`mufric {path[0]}`]({anchor_of(path)}): {markdown_text(description)}"
        if path in children:
            line += ": " + links(path)
        lines.append(line)
    return "\n".join(lines) + "\n"


def wrap(key, body):
    return BEGIN.format(key) + "\n" + body + END + "\n"


def main(argv):
    args = [a for a in argv[1:] if a != "--write"]
    write = "--write" in argv[1:]
    if len(args) != 2 or any(a.startswith("-") for a in args):
        print(__doc__.split("Usage:")[1].split("\n\n")[0].rstrip(), file=sys.stderr)
        return 2
    binary, usage_md = os.path.abspath(args[0]), args[1]
    if not os.access(binary, os.X_OK):
        fail(f"{args[0]}: not an executable")
    try:
        with open(usage_md, encoding="utf-8") as f:
            doc = f.read()
    except OSError as error:
        fail(str(error))

    commands = walk(binary)
    known = {path for path, _, _ in commands}
    wanted = {key_of(path): block_body(text) for path, text, _ in commands}
    wanted[TOC_KEY] = toc_body(commands)
    wanted[SCENE_KEYS_KEY] = raw_help(binary, ["micro", "keys"], flag=None).rstrip("\n") + "\n"

    # A machine-specific path that no normalisation above catches must not reach the document.
    here = {os.path.dirname(binary), os.path.dirname(os.path.dirname(os.path.abspath(usage_md))),
            os.path.expanduser("~")}
    for key, body in wanted.items():
        for path in here:
            if len(path) > 1 and re.search(re.escape(path) + r"(/|\b)", body):
                fail(f"`{key}` prints {path}, a path of this machine: normalise it in "
                     "tools/usage_reference.py's NORMALISATIONS")

    blocks = {m.group(1): m for m in BLOCK_RE.finditer(doc)}
    headings = {}
    for m in HEADING_RE.finditer(doc):
        headings[tuple(m.group(1).split()[1:])] = m
    problems = []
    for key, m in blocks.items():
        if key not in wanted:
            problems.append(f"generated block `{key}`: the binary has no such command; remove the block "
                            "(and move or drop its section's prose) by hand")
    for path, m in headings.items():
        if path not in known:
            problems.append(f"heading `## {title_of(path)}` (line {doc.count(chr(10), 0, m.start()) + 1}): "
                            f"the binary has no command `{title_of(path)}`; remove or rename the section by hand")

    drift = []
    for path, _, _ in commands:
        key = key_of(path)
        if key not in blocks:
            drift.append((key, "missing" + ("" if path in headings else ", and no heading `## " + title_of(path) + "`")))
        elif blocks[key].group(2) != wanted[key]:
            drift.append((key, "differs from the binary's help"))
        elif path not in headings:
            drift.append((key, f"has no heading `## {title_of(path)}`"))
    if SCENE_KEYS_KEY not in blocks:
        drift.append((SCENE_KEYS_KEY, "missing (the scene keys' reference)"))
    elif blocks[SCENE_KEYS_KEY].group(2) != wanted[SCENE_KEYS_KEY]:
        drift.append((SCENE_KEYS_KEY, "differs from the scene reader's keys"))
    if TOC_KEY not in blocks:
        drift.append((TOC_KEY, "missing (the table of contents' list of commands)"))
    elif blocks[TOC_KEY].group(2) != wanted[TOC_KEY]:
        drift.append((TOC_KEY, "differs from the binary's commands (the table of contents' list)"))

    if not write:
        for key, what in drift:
            print(f"{usage_md}: generated block `{key}` {what}")
            if key in blocks and "differs" in what:
                diff = difflib.unified_diff(blocks[key].group(2).splitlines(), wanted[key].splitlines(),
                                            "usage.md", "binary", lineterm="", n=0)
                for line in list(diff)[2:14]:
                    print("    " + line)
        for problem in problems:
            print(f"{usage_md}: {problem}")
        if drift:
            print(f"refresh the generated blocks with: python3 {argv[0]} {args[0]} {usage_md} --write")
        if drift or problems:
            return 1
        print(f"{usage_md}: the generated option reference of {len(commands)} commands is current")
        return 0

    # --write: replace blocks in place (from the end, so offsets stay valid), then add what is missing.
    for key, m in sorted(blocks.items(), key=lambda item: -item[1].start()):
        if key in wanted:
            doc = doc[:m.start()] + wrap(key, wanted[key]) + doc[m.end():]
    added = []
    for path, _, _ in commands:
        key = key_of(path)
        if key in blocks:
            if path not in headings:  # a block whose heading went: put the heading back above it
                at = doc.index(BEGIN.format(key))
                doc = doc[:at] + f"## {title_of(path)}\n\n" + doc[at:]
            continue
        heading = next((m for m in HEADING_RE.finditer(doc) if tuple(m.group(1).split()[1:]) == path), None)
        if heading:
            at = heading.end() + 1
            doc = doc[:at] + "\n" + wrap(key, wanted[key]) + doc[at:]
        else:
            at = doc.find(END_OF_COMMANDS)
            section = f"## {title_of(path)}\n\n" + wrap(key, wanted[key]) + "\n"
            if at < 0:
                doc = doc.rstrip("\n") + "\n\n" + section
            else:
                doc = doc[:at] + section + doc[at:]
            added.append(title_of(path))
    if SCENE_KEYS_KEY not in blocks:
        scenes = re.search(r"^## Scenes[ \t]*$", doc, re.M)
        after = re.search(r"^## ", doc[scenes.end():], re.M) if scenes else None
        at = scenes.end() + after.start() if after else len(doc)
        doc = doc[:at].rstrip("\n") + "\n\n" + SCENE_KEYS_SECTION + wrap(SCENE_KEYS_KEY, wanted[SCENE_KEYS_KEY]) + "\n" + doc[at:]
    if TOC_KEY not in blocks:
        first = re.search(r"^## ", doc, re.M)
        at = first.start() if first else len(doc)
        doc = doc[:at] + wrap(TOC_KEY, wanted[TOC_KEY]) + "\n" + doc[at:]
    with open(usage_md, "w", encoding="utf-8") as f:
        f.write(doc)
    print(f"{usage_md}: {len(commands)} commands' blocks written"
          + (f"; new sections (write their prose): {', '.join(added)}" if added else ""))
    for problem in problems:
        print(f"{usage_md}: {problem}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
