#!/usr/bin/env python3
"""Runs every shell example of README.md and docs/*.md, as a user would after `make demo` (run
first: scripts/demo.sh), and checks each command's exit status against the one its text
promises.

    scripts/doc-examples.py [--list] [--build DIR] [FILE.md ...]

The ```sh blocks of a file run in one bash process from the repository root, in order (later
ones use what earlier ones set and wrote, as a reader following the text does).
A command passes when it exits 0, or the status its line ends with (`# exit 3`). Lines that
are only comments are the text's illustration of output and are not run, nor are `make`
commands (the examples run after the build, which they would configure again).

A block that cannot run here is preceded by `<!-- example: skip REASON -->` (the benchmark
assets take minutes to make, a Blender or Slurm installation, a command that runs this very
suite); --list prints every block with what it is and why it is skipped. Exits 1 naming each
file:line whose command broke its promise, 2 on bad use.
"""
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKIP = re.compile(r"<!--\s*example:\s*skip\s+(.*?)\s*-->")
PROMISE = re.compile(r"#\s*exit\s+(\d+)\b")


def blocks(path):
    """(first line number, lines, skip reason or None) of each ```sh block."""
    out, lines = [], open(path, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].strip() == "```sh":
            reason = None
            for back in range(i - 1, max(-1, i - 3), -1):
                m = SKIP.search(lines[back])
                if m:
                    reason = m.group(1)
                    break
                if lines[back].strip():
                    break
            start, body = i + 2, []
            i += 1
            while i < len(lines) and lines[i].strip() != "```":
                body.append(lines[i])
                i += 1
            out.append((start, body, reason))
        i += 1
    return out


def commands(start, body):
    """(line number, text, expected status) of each command: backslash continuations and
    here-documents joined, comment-only lines dropped."""
    out, i = [], 0
    while i < len(body):
        line, number = body[i], start + i
        i += 1
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        text = line
        # Continued lines, and a quoted string over several lines (python3 -c "...").
        while (text.rstrip().endswith("\\") or text.count('"') % 2) and i < len(body):
            text += "\n" + body[i]
            i += 1
        # A loop or a condition runs whole: to its `done` or `fi`.
        depth = len(re.findall(r"\b(do|then)\s*(#.*)?$", text)) - len(
            re.findall(r"^\s*(done|fi)\b", text))
        while depth > 0 and i < len(body):
            text += "\n" + body[i]
            depth += len(re.findall(r"\b(do|then)\s*(#.*)?$", body[i]))
            depth -= len(re.findall(r"^\s*(done|fi)\b", body[i]))
            i += 1
        heredoc = re.search(r"<<-?\s*'?(\w+)'?", text)
        if heredoc:
            end = heredoc.group(1)
            while i < len(body):
                text += "\n" + body[i]
                i += 1
                if body[i - 1].strip() == end:
                    break
        if re.match(r"\s*make\b", text):
            continue  # the build's own targets: the examples run after it
        first_line = text.split("\n")[0]
        promise = PROMISE.search(first_line) or PROMISE.search(text.split("\n")[-1])
        out.append((number, text, int(promise.group(1)) if promise else 0))
    return out


def script(path, cmds):
    """A bash script that runs `cmds` and reports each broken promise."""
    out = ["cd " + ROOT]
    for number, text, expected in cmds:
        where = f"{os.path.relpath(path, ROOT)}:{number}"
        out.append("{\n" + text + "\n} 2>\"$err\"")
        out.append(
            f'status=$?; if [ $status -ne {expected} ]; then echo "{where}: exit $status, '
            f'the text promises {expected}: $(tail -n 1 "$err")" >&2; failed=1; fi')
    return ('failed=0\nerr=$(mktemp)\n' + "\n".join(out) +
            '\nrm -f "$err"\nexit $failed\n')


def main(argv):
    listing = "--list" in argv
    argv = [a for a in argv if a != "--list"]
    build = "build"
    if "--build" in argv:
        i = argv.index("--build")
        if i + 1 >= len(argv):
            sys.exit("doc-examples.py: --build needs a folder")
        build = argv[i + 1]
        del argv[i:i + 2]
    files = argv or [os.path.join(ROOT, "README.md")] + sorted(
        os.path.join(ROOT, "docs", f) for f in os.listdir(os.path.join(ROOT, "docs"))
        if f.endswith(".md"))
    env = dict(os.environ, CI="1")
    if build != "build":
        env["DISPEX_BUILD"] = build
    ran = skipped = 0
    failed = []
    if not listing:  # what the text assumes: the demo's outputs in out/demo
        subprocess.run([os.path.join(ROOT, "scripts", "demo.sh"), build], cwd=ROOT, env=env,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    for path in files:
        # A file's blocks run in one shell, in order: a reader's shell keeps what earlier
        # blocks set ($cage) and wrote.
        cmds = []
        for start, body, reason in blocks(path):
            where = f"{os.path.relpath(path, ROOT)}:{start - 1}"
            if listing:
                print(f"{where}: {'skip: ' + reason if reason else 'runs'} "
                      f"({len(commands(start, body))} commands)")
            elif reason:
                skipped += 1
            else:
                ran += 1
                cmds += commands(start, body)
        if listing or not cmds:
            continue
        with tempfile.NamedTemporaryFile("w", suffix=".sh", delete=False) as f:
            f.write(script(path, cmds))
        result = subprocess.run(["bash", f.name], env=env, stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True)
        os.unlink(f.name)
        if result.returncode != 0:
            broken = [l for l in result.stderr.splitlines() if "the text promises" in l]
            failed += broken or [f"{path}: {result.stderr.strip()[-300:]}"]
    if listing:
        return 0
    print(f"doc-examples: {ran} blocks ran, {skipped} skipped as marked, "
          f"{len(failed)} broken promises", file=sys.stderr)
    for line in failed:
        print("  " + line, file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
