#!/usr/bin/env python3
"""Reads a Parquet file with pyarrow (an independent client) and checks it against a JSON spec:
{"rows": N, "columns": {"name": "double", ...}, "units": {"name": "rad"}, "metadata": {"key": "value"},
 "values": {"name": [[row, value], ...]}}. Prints one line per check; exits 1 on any failure."""
import json
import math
import sys

import pyarrow.parquet as pq


def main():
    path, spec_path = sys.argv[1], sys.argv[2]
    spec = json.load(open(spec_path))
    table = pq.read_table(path)
    failures = 0

    def check(ok, what):
        nonlocal failures
        print(("PASS " if ok else "FAIL ") + what)
        failures += 0 if ok else 1

    if "rows" in spec:
        check(table.num_rows == spec["rows"], f"rows {table.num_rows} == {spec['rows']}")
    for name, typ in spec.get("columns", {}).items():
        field = table.schema.field(name) if name in table.schema.names else None
        check(field is not None and str(field.type) == typ, f"column {name}: {field.type if field else None} == {typ}")
    for name, unit in spec.get("units", {}).items():
        md = table.schema.field(name).metadata or {}
        got = md.get(b"unit", b"").decode()
        check(got == unit, f"unit of {name}: {got!r} == {unit!r}")
    md = table.schema.metadata or {}
    for key, value in spec.get("metadata", {}).items():
        got = md.get(key.encode(), b"").decode()
        check(got == value, f"metadata {key}: {got!r} == {value!r}")
    for name, pairs in spec.get("values", {}).items():
        col = table.column(name).to_pylist()
        for row, want in pairs:
            got = col[row]
            ok = (math.isclose(got, want, rel_tol=1e-12, abs_tol=1e-12)
                  if isinstance(want, float) else got == want)
            check(ok, f"{name}[{row}] = {got!r} == {want!r}")
    print(f"{'OK' if failures == 0 else 'FAILED'}: {failures} failed check(s)")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
