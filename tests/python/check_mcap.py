#!/usr/bin/env python3
"""Check a pendulum run file (MCAP) with the official Python `mcap` reader.

An independent client: if this script reads what the Rust writer wrote, so can Foxglove and any
other MCAP tool.

Usage: check_mcap.py FILE.mcap EXPECTED.json

EXPECTED.json:
    {
      "library": "pendulum/0.1",                  # optional: the MCAP header's library
      "topics": {                                 # exactly the channels the file must have
        "/encoder": {
          "count": 3000,                          # messages on the topic
          "schema_name": "pendulum.Encoder",      # optional
          "messages": [                           # optional samples, by index in file order
            {"index": 0, "log_time": 4294000000000, "data": {"t_s": 0.0, ...}}
          ]
        }
      },
      "metadata": {"run": {"id": "r01"}, ...}     # optional: exact metadata records by name
    }

Checks: chunk CRCs (validate_crcs=True), channel set, schema encoding `jsonschema` and a
draft 2020-12 schema, message encoding `json`, every message against its schema's required keys
and property types, count per topic (also against the file's statistics), non-decreasing
log_time per topic in file order, publish_time == log_time, sampled messages (floats to 1e-9
relative, integers exactly), metadata. Prints one line per check; exits 1 on any failure, 2 on
bad usage.
"""

import json
import math
import sys

DRAFT_2020_12 = "https://json-schema.org/draft/2020-12/schema"


class Checker:
    def __init__(self):
        self.failures = 0

    def check(self, ok, what, detail=""):
        line = ("PASS " if ok else "FAIL ") + what
        if detail and not ok:
            line += ": " + detail
        print(line, flush=True)
        if not ok:
            self.failures += 1
        return ok


def type_ok(ty, value):
    if ty == "object":
        return isinstance(value, dict)
    if ty == "array":
        return isinstance(value, list)
    if ty == "string":
        return isinstance(value, str)
    if ty == "boolean":
        return isinstance(value, bool)
    if ty == "integer":
        return isinstance(value, int) and not isinstance(value, bool)
    if ty == "number":
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    return True  # keyword we do not check


def schema_errors(schema, value, at="$"):
    """Required keys, property types, integer bounds, array items; enough for our schemas."""
    errors = []
    ty = schema.get("type")
    if ty is not None and not type_ok(ty, value):
        return [f"{at}: expected {ty}, found {value!r}"]
    if ty == "integer":
        if "minimum" in schema and value < schema["minimum"]:
            errors.append(f"{at}: {value} < minimum {schema['minimum']}")
        if "maximum" in schema and value > schema["maximum"]:
            errors.append(f"{at}: {value} > maximum {schema['maximum']}")
    if isinstance(value, dict):
        props = schema.get("properties", {})
        for key in schema.get("required", []):
            if key not in value:
                errors.append(f"{at}: missing required key {key}")
        for key, sub in value.items():
            if key in props:
                errors.extend(schema_errors(props[key], sub, f"{at}.{key}"))
            elif schema.get("additionalProperties") is False:
                errors.append(f"{at}: unexpected key {key}")
    if isinstance(value, list) and isinstance(schema.get("items"), dict):
        for i, item in enumerate(value):
            errors.extend(schema_errors(schema["items"], item, f"{at}[{i}]"))
    return errors


def diff(expected, actual, at="$"):
    """First difference between expected and actual JSON values, or None."""
    if isinstance(expected, bool) or isinstance(actual, bool):
        return None if expected is actual else f"{at}: expected {expected!r}, got {actual!r}"
    if isinstance(expected, int) and isinstance(actual, int):
        return None if expected == actual else f"{at}: expected {expected}, got {actual}"
    if isinstance(expected, (int, float)) and isinstance(actual, (int, float)):
        if math.isclose(float(expected), float(actual), rel_tol=1e-9, abs_tol=0.0):
            return None
        return f"{at}: expected {expected!r}, got {actual!r}"
    if isinstance(expected, dict) and isinstance(actual, dict):
        if set(expected) != set(actual):
            return f"{at}: keys {sorted(actual)} != expected {sorted(expected)}"
        for key in expected:
            d = diff(expected[key], actual[key], f"{at}.{key}")
            if d:
                return d
        return None
    if isinstance(expected, list) and isinstance(actual, list):
        if len(expected) != len(actual):
            return f"{at}: length {len(actual)} != expected {len(expected)}"
        for i, (e, a) in enumerate(zip(expected, actual)):
            d = diff(e, a, f"{at}[{i}]")
            if d:
                return d
        return None
    return None if expected == actual else f"{at}: expected {expected!r}, got {actual!r}"


def main(argv):
    if len(argv) != 3:
        print("usage: check_mcap.py FILE.mcap EXPECTED.json", file=sys.stderr)
        return 2
    mcap_path, expected_path = argv[1], argv[2]
    with open(expected_path, encoding="utf-8") as f:
        expected = json.load(f)
    exp_topics = expected.get("topics", {})
    c = Checker()

    try:
        from mcap.reader import make_reader
    except ImportError as e:
        c.check(False, "import mcap", str(e))
        return 1

    try:
        with open(mcap_path, "rb") as f:
            reader = make_reader(f, validate_crcs=True)
            header = reader.get_header()
            summary = reader.get_summary()
            # File order (not log-time order), so per-topic ordering is really checked.
            records = []
            for schema, channel, message in reader.iter_messages(log_time_order=False):
                records.append((channel.topic, message.log_time, message.publish_time,
                                bytes(message.data)))
            metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    except Exception as e:  # McapError, ValueError (CRC), struct.error, ...: all mean "bad file"
        c.check(False, f"read {mcap_path} with validate_crcs=True", f"{type(e).__name__}: {e}")
        return 1
    c.check(True, f"read {mcap_path} with validate_crcs=True ({len(records)} messages)")

    if "library" in expected:
        c.check(header.library == expected["library"], f"header library {expected['library']!r}",
                f"got {header.library!r}")
    c.check(header.profile == "", "header profile empty", f"got {header.profile!r}")

    if summary is None:
        c.check(False, "summary section present")
        return 1
    channels = {ch.topic: ch for ch in summary.channels.values()}
    c.check(set(channels) == set(exp_topics), f"channels {sorted(exp_topics)}",
            f"file has {sorted(channels)}")

    schemas = {}
    for topic, ch in sorted(channels.items()):
        schema = summary.schemas.get(ch.schema_id)
        if not c.check(schema is not None, f"{topic}: has a schema"):
            continue
        c.check(schema.encoding == "jsonschema", f"{topic}: schema encoding jsonschema",
                f"got {schema.encoding!r}")
        c.check(ch.message_encoding == "json", f"{topic}: message encoding json",
                f"got {ch.message_encoding!r}")
        want_name = exp_topics.get(topic, {}).get("schema_name")
        if want_name is not None:
            c.check(schema.name == want_name, f"{topic}: schema name {want_name}",
                    f"got {schema.name!r}")
        try:
            parsed = json.loads(schema.data)
        except ValueError as e:
            c.check(False, f"{topic}: schema is JSON", str(e))
            continue
        c.check(parsed.get("$schema") == DRAFT_2020_12, f"{topic}: schema is draft 2020-12",
                f"$schema = {parsed.get('$schema')!r}")
        schemas[topic] = parsed

    by_topic = {}
    for topic, log_time, publish_time, data in records:
        by_topic.setdefault(topic, []).append((log_time, publish_time, data))

    stats_counts = {}
    if summary.statistics is not None:
        for ch_id, n in summary.statistics.channel_message_counts.items():
            if ch_id in summary.channels:
                stats_counts[summary.channels[ch_id].topic] = n

    for topic in sorted(exp_topics):
        spec = exp_topics[topic]
        msgs = by_topic.get(topic, [])
        if "count" in spec:
            c.check(len(msgs) == spec["count"], f"{topic}: count {spec['count']}",
                    f"got {len(msgs)}")
        if topic in stats_counts:
            c.check(stats_counts[topic] == len(msgs),
                    f"{topic}: statistics record count {stats_counts[topic]} = messages read",
                    f"read {len(msgs)}")

        bad_order = next((i for i in range(1, len(msgs)) if msgs[i][0] < msgs[i - 1][0]), None)
        c.check(bad_order is None, f"{topic}: log_time non-decreasing in file order",
                f"message {bad_order} goes back in time" if bad_order is not None else "")
        bad_pub = next((i for i, m in enumerate(msgs) if m[1] != m[0]), None)
        c.check(bad_pub is None, f"{topic}: publish_time == log_time",
                f"message {bad_pub}" if bad_pub is not None else "")

        decoded, first_error = [], None
        for i, (_, _, data) in enumerate(msgs):
            try:
                value = json.loads(data)
            except ValueError as e:
                first_error = first_error or f"message {i}: not JSON: {e}"
                decoded.append(None)
                continue
            decoded.append(value)
            if topic in schemas and first_error is None:
                errs = schema_errors(schemas[topic], value)
                if errs:
                    first_error = f"message {i}: {errs[0]}"
        c.check(first_error is None, f"{topic}: all {len(msgs)} messages are JSON matching the schema",
                first_error or "")

        for sample in spec.get("messages", []):
            i = sample["index"]
            what = f"{topic}[{i}]"
            if not c.check(0 <= i < len(msgs), f"{what}: exists", f"only {len(msgs)} messages"):
                continue
            if "log_time" in sample:
                c.check(msgs[i][0] == sample["log_time"], f"{what}: log_time {sample['log_time']}",
                        f"got {msgs[i][0]}")
            if "data" in sample:
                d = diff(sample["data"], decoded[i])
                c.check(d is None, f"{what}: fields equal", d or "")

    for name, want in sorted(expected.get("metadata", {}).items()):
        got = metadata.get(name)
        c.check(got == want, f"metadata {name!r}", f"got {got!r}")
    if "metadata" in expected:
        c.check(set(metadata) == set(expected["metadata"]),
                f"metadata names {sorted(expected['metadata'])}", f"file has {sorted(metadata)}")

    print(f"{'OK' if c.failures == 0 else 'FAILED'}: {c.failures} failed check(s)")
    return 1 if c.failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
