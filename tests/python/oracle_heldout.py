#!/usr/bin/env python3
"""Could any held-out judge have confirmed a survey miss? Scores the truth itself on the validate runs.

A survey case that `discover` does not name is either a miss of the method or a campaign whose
validate runs hold no evidence of the hidden effect. This tells them apart: it synthesises the
kept twin case, runs `discover` (for its base fit), then `pendulum validate`s three models on the
validate runs, each with its initial states refitted per run:

  truth      the case's damping (a, b, mu) and the hidden effect at its true size
  truth-base the same damping without the effect
  fit-base   discover's fitted base model (as discover compares against it)

and prints each run's E_theta and the sums. If the truth does not beat the fitted base, no rule
that judges on the held-out runs can name the effect on this campaign.

Usage:
  SURVEY_KEEP=DIR SURVEY_ONE=effect:k cargo test --release --test integration \\
      survey_issue_5_every_effect -- --ignored --nocapture   # writes DIR/case.toml first
  oracle_heldout.py target/release/pendulum DIR/case.toml OUT MODEL key=value ...

MODEL is the params.parquet model name of the truth (e.g. reference+stribeck); key=value sets a
params.parquet column (a, b, mu go to both truth models, the rest to the truth only), e.g.
  a=0 b=0.5 mu=0.15 stribeck.T_s=0.00767 stribeck.v_s=0.340
"""
import os
import subprocess
import sys

import pyarrow as pa
import pyarrow.parquet as pq

DAMPING = ("a", "b", "mu")


def run(cmd):
    env = dict(os.environ, RAYON_NUM_THREADS=os.environ.get("RAYON_NUM_THREADS", "1"))
    return subprocess.run(cmd, check=True, capture_output=True, text=True, env=env).stdout


def set_col(table, name, value):
    i = table.schema.get_field_index(name)
    if i < 0:
        sys.exit(f"params.parquet has no column {name!r}")
    field = table.schema.field(i)
    return table.set_column(i, field, pa.array([value], type=field.type))


def validate_e(binary, data, params, out):
    text = run([binary, "validate", data, "--params", params, "--out", out])
    rows = [l.split() for l in text.splitlines() if "validate E_θ=" in l]
    return {r[0]: float(r[3]) for r in rows}


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    binary, case, out, model = sys.argv[1:5]
    sets = [a.split("=", 1) for a in sys.argv[5:]]
    os.makedirs(out, exist_ok=True)
    data = os.path.join(out, "data")
    run([binary, "synth", case, data])
    disc = os.path.join(out, "discover")
    run([binary, "discover", data, "--generations", "300", "--out", disc, "--quiet"])
    fitted = pq.read_table(os.path.join(disc, "params.parquet")).slice(0, 1)
    meta = fitted.schema.metadata
    base = fitted
    for k, v in sets:
        if k in DAMPING:
            base = set_col(base, k, float(v))
    truth = set_col(base, "model", model)
    for k, v in sets:
        if k not in DAMPING:
            truth = set_col(truth, k, float(v))
    results = {}
    for name, table in (("truth", truth), ("truth-base", base), ("fit-base", fitted)):
        path = os.path.join(out, f"{name}.parquet")
        # Uncompressed: the reader is built without snappy.
        pq.write_table(table.replace_schema_metadata(meta), path, compression="none")
        results[name] = validate_e(binary, data, path, os.path.join(out, f"validate-{name}"))
    for name, e in results.items():
        runs = "  ".join(f"{r} {v:.4f}" for r, v in sorted(e.items()))
        print(f"{name:<10} sum E_θ {sum(e.values()):8.4f}   {runs}")
    t, f = sum(results["truth"].values()), sum(results["fit-base"].values())
    print(f"the truth's held-out E_θ fall over the fitted base: {100 * (1 - t / f):+.1f} %")


if __name__ == "__main__":
    main()
