#!/usr/bin/env python3
"""Opens every table `pendulum identify` writes with pyarrow and checks the documented schemas."""
import sys

import pyarrow.parquet as pq

SCHEMAS = {
    "params.parquet": {"model": "string", "a": "double", "b": "double", "mu": "double", "alpha": "double",
                       "beta": "double", "M": "double", "f_obj": "double", "e_theta": "double",
                       "n_runs": "int64", "generations": "int64", "evaluations": "int64",
                       "wall_s": "double", "seed": "int64", "scope": "string", "run_id": "string"},
    "initial_conditions.parquet": {"run_id": "string", "model": "string", "theta0_est": "double",
                                   "theta_dot0_est": "double", "theta0_fit": "double",
                                   "theta_dot0_fit": "double"},
    "residuals.parquet": {"run_id": "string", "model": "string", "role": "string", "mode": "string", "segment": "int64", "t": "double",
                          "tau_s": "double", "theta_meas": "double", "theta_sim": "double",
                          "residual": "double", "theta_dot_meas": "double", "theta_dot_sim": "double",
                          "scope": "string"},
    "convergence.parquet": {"generation": "int64", "best": "double", "worst": "double", "mean": "double"},
    "runs.parquet": {"run_id": "string", "role": "string", "omega_hz": "double", "t0_s": "double",
                     "measured_steady": "string", "simulated_steady": "string"},
}
UNITS = {"params.parquet": {"b": "N·s/m", "a": "kg/m"}, "residuals.parquet": {"theta_meas": "rad", "tau_s": "s"}}
CLASSES = {"rest", "oscillation", "rotation_ccw", "rotation_cw", "chaos", "-"}


def main():
    out = sys.argv[1]
    failures = 0
    for name, cols in SCHEMAS.items():
        t = pq.read_table(f"{out}/{name}")
        for col, typ in cols.items():
            ok = col in t.schema.names and str(t.schema.field(col).type) == typ
            print(("PASS " if ok else "FAIL ") + f"{name}: {col} is {typ}")
            failures += not ok
        for col, unit in UNITS.get(name, {}).items():
            got = (t.schema.field(col).metadata or {}).get(b"unit", b"").decode()
            print(("PASS " if got == unit else "FAIL ") + f"{name}: unit of {col} {got!r}")
            failures += got != unit
        md = t.schema.metadata or {}
        ok = b"pipeline" in md and b"pendulum_version" in md
        print(("PASS " if ok else "FAIL ") + f"{name}: pipeline and version in key-value metadata")
        failures += not ok
        ok = t.num_rows > 0
        print(("PASS " if ok else "FAIL ") + f"{name}: {t.num_rows} rows")
        failures += not ok
    runs = pq.read_table(f"{out}/runs.parquet").to_pylist()
    bad = [r for r in runs if r["measured_steady"] not in CLASSES or r["simulated_steady"] not in CLASSES]
    print(("PASS " if not bad else "FAIL ") + "steady-state names")
    failures += bool(bad)
    print(f"{'OK' if failures == 0 else 'FAILED'}: {failures} failed check(s)")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
