#!/usr/bin/python3
"""Run one of the C unit-test programs and write its PASS/FAIL lines as a JUnit XML file, so that
`catkin_make run_tests` (catkin_run_tests_target) and catkin_test_results see the unit tests like any ROS test.
    junit_wrap.py XML_OUT PROGRAM [ARGS...]
Exit status: the program's (a crash without a FAIL line is a failure named after the program)."""
import os
import subprocess
import sys
from xml.sax.saxutils import escape, quoteattr


def main():
    out, cmd = sys.argv[1], sys.argv[2:]
    name = os.path.basename(cmd[0])
    p = subprocess.run(cmd, capture_output=True, text=True)
    cases, detail = [], []
    for line in p.stdout.splitlines():
        if line.startswith(("PASS ", "FAIL ")):
            cases.append((line[5:].strip(), line.startswith("FAIL"), "\n".join(detail)))
            detail = []
        else:
            detail.append(line)
    if p.returncode != 0 and not any(failed for _, failed, _ in cases):
        cases.append((name, True, f"exit status {p.returncode}\n{p.stderr[-4000:]}"))
    failures = sum(failed for _, failed, _ in cases)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w") as f:
        f.write('<?xml version="1.0" encoding="utf-8"?>\n')
        f.write(f'<testsuite name={quoteattr(name)} tests="{len(cases)}" failures="{failures}" errors="0">\n')
        for case, failed, text in cases:
            f.write(f'  <testcase classname={quoteattr(name)} name={quoteattr(case)}>')
            if failed:
                f.write(f'<failure message="failed">{escape(text)}</failure>')
            f.write("</testcase>\n")
        f.write("</testsuite>\n")
    sys.stdout.write(p.stdout)
    return p.returncode


if __name__ == "__main__":
    sys.exit(main())
