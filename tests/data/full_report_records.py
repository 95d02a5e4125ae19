"""Writes ``full_report_records.json.gz``: scene, method, params, status and metrics of
every run of a full report's ``results.json`` (no fields, timings or machine), the
records tests/pdverify/test_quoted_numbers.py resolves the report's quoted numbers
against. Regenerate after a change of the numbers:

    python tests/data/full_report_records.py REPORT/results.json
"""
import gzip
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "full_report_records.json.gz")


def main(path: str) -> None:
    with open(path) as fh:
        report = json.load(fh)
    runs = [{k: r[k] for k in ("scene", "method", "params", "status", "metrics")}
            for r in report["runs"]]
    data = {"source": f"{os.path.basename(path)} of pdverify {report['pdverify_version']}, "
                      f"created {report['created']}", "runs": runs}
    with gzip.open(OUT, "wt") as fh:
        json.dump(data, fh, sort_keys=True)


if __name__ == "__main__":
    main(sys.argv[1])
