#!/usr/bin/python3
"""Print PASS/FAIL lines for every test case in rostest's JUnit XML results (scripts/test counts them).
usage: junit_summary.py RESULTS_DIR PREFIX"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def main():
    results, prefix = sys.argv[1], sys.argv[2]
    files = sorted(glob.glob(os.path.join(results, "**", "*.xml"), recursive=True))
    if not files:
        print(f"FAIL {prefix}.no_results")
        return 1
    failed = 0
    for path in files:
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as e:
            print(f"FAIL {prefix}.{os.path.basename(path)} (unreadable: {e})")
            failed += 1
            continue
        suites = [root] if root.tag == "testsuite" else root.iter("testsuite")
        for suite in suites:
            for case in suite.iter("testcase"):
                bad = case.find("failure") is not None or case.find("error") is not None
                name = case.get("name", "?")
                if bad:
                    msg = (case.find("failure") if case.find("failure") is not None else case.find("error"))
                    print(f"  {(msg.get('message') or msg.text or '').strip()[:500]}")
                print(f"{'FAIL' if bad else 'PASS'} {prefix}.{name}")
                failed += bad
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
