#!/usr/bin/env python3
"""Fails on a skipped test that tests/allowed-skips.txt does not allow.

ctest exits 0 when tests are skipped, so a test that stopped running (a missing tool, a
changed environment) would pass silently. This reads ctest's JUnit report
(`ctest --output-junit FILE`) and checks every test that did not run against the list of
skips a machine may show, each with the reason its output must give.

  scripts/check-skips.py JUNIT.xml [ALLOWED]   (ALLOWED: default tests/allowed-skips.txt)
Exit 0: every skip allowed (each is listed with its reason); 1: a skip not allowed; 2: bad input.
"""
import os
import re
import sys
import xml.etree.ElementTree as ET


def load_allowed(path):
    rules = []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            fields = [x.strip() for x in line.split(" | ")]
            if len(fields) != 3 or not all(fields):
                sys.exit(f"check-skips: {path}:{number}: expected 'NAME-REGEX | REASON-REGEX | WHY'")
            try:
                rules.append((re.compile(fields[0]), re.compile(fields[1]), fields[2]))
            except re.error as e:
                sys.exit(f"check-skips: {path}:{number}: {e}")
    return rules


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: scripts/check-skips.py JUNIT.xml [ALLOWED]")
    junit = sys.argv[1]
    allowed_path = sys.argv[2] if len(sys.argv) == 3 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "tests", "allowed-skips.txt")
    rules = load_allowed(allowed_path)
    try:
        root = ET.parse(junit).getroot()
    except (OSError, ET.ParseError) as e:
        print(f"check-skips: {junit}: {e}", file=sys.stderr)
        return 2
    ran = 0
    allowed, refused = [], []
    for case in root.iter("testcase"):
        name = case.get("name", "")
        if case.get("status") == "run":
            ran += 1
            continue
        if case.find("failure") is not None:
            continue  # a failure, which ctest already reported and failed on
        output = case.findtext("system-out") or ""
        why = next((w for n, r, w in rules if n.fullmatch(name) and r.search(output)), None)
        if why is None:
            reason = next((l.strip() for l in output.splitlines() if l.strip()), "no output")
            refused.append(f"{name}: {reason}")
        else:
            allowed.append((name, why))
    if ran == 0:
        print(f"check-skips: {junit}: no test ran", file=sys.stderr)
        return 1
    print(f"check-skips: {ran} ran, {len(allowed)} skipped as allowed, {len(refused)} skipped "
          f"otherwise")
    reasons = {}
    for name, why in allowed:
        reasons.setdefault(why, []).append(name)
    for why, names in sorted(reasons.items()):
        print(f"check-skips: {len(names)} skipped, allowed: {why}")
    if refused:
        print(f"check-skips: {len(refused)} skipped test(s) not allowed by {os.path.relpath(allowed_path)}:",
              file=sys.stderr)
        for line in refused:
            print(f"  {line}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
