"""Reading a recorded benchmark run's files: shared by the run scripts beside this one.

`nesy bench run --record-cassettes` writes `results/*.jsonl` (one record per line, a unit
resumed after an interruption appearing again) and `cassettes/<scenario>/<method>.json`
(every model call with its request and reply). The scripts that re-score a run, tabulate its
figures and list what the model got wrong read them through these functions, so that a unit's
identity, a re-ask and a verifier's rejection mean one thing in all of them. Bad input ends
the calling script with exit 2 and a message naming the file and line. Standard library only.
"""

import json
import sys
from pathlib import Path

# The first words of a correction that reports the symbolic verifier's rejection of a reply
# it read, as opposed to a reply the parser could not read.
VERIFIER_HEADINGS = ("the symbolic verifier rejected", "this patch was rejected")


def fail_input(message):
    """Ends the calling script with exit 2, the message prefixed by the script's name."""
    print(f"{Path(sys.argv[0]).stem}: {message}", file=sys.stderr)
    sys.exit(2)


def last_records(run):
    """The last record of every unit of a run folder, keyed by (scenario, variant, repeat)."""
    files = sorted((run / "results").glob("*.jsonl"))
    if not files:
        fail_input(f"{run / 'results'}: no results files (*.jsonl); is this a benchmark run folder?")
    records = {}
    for path in files:
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            if not line.strip():
                continue
            try:
                record = json.loads(line)
                key = (record["scenario"], record["variant"], record["repeat"])
            except (json.JSONDecodeError, KeyError, TypeError) as error:
                fail_input(f"{path}:{number}: not a unit record ({error})")
            records[key] = record
    return records


def interactions(path):
    """The recorded calls of a cassette file."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))["interactions"]
    except (OSError, json.JSONDecodeError, KeyError, TypeError) as error:
        fail_input(f"{path}: not a cassette ({error})")


def cassette_of(run, scenario, variant):
    """A unit's cassette file in a run folder."""
    return run / "cassettes" / scenario / f"{variant}.json"


def has_unordered_twins(calls):
    """Whether a cassette holds identical requests (same key) without their send order.
    Concurrent identical requests complete in any order; a cassette that kept no send order
    (recorded before it was stored) may replay their replies to each other's callers."""
    seen = set()
    for call in calls:
        key = call.get("key")
        if key in seen and call.get("send_order") is None:
            return True
        seen.add(key)
    return False


def text_of(content):
    """A message's text, whether it is a string or a list of parts."""
    if isinstance(content, str):
        return content
    return "\n".join(part.get("text", "") for part in content if isinstance(part, dict))


def reask(interaction):
    """For a re-ask (a conversation that ends in nesy's correction of the model's previous
    reply), the pair (that reply, the correction) as text; None for a first try."""
    request = interaction.get("request", {})
    messages = request.get("body", request).get("messages", [])
    if len(messages) < 3 or messages[-2].get("role") != "assistant":
        return None
    return text_of(messages[-2].get("content", "")), text_of(messages[-1].get("content", ""))


def is_verifier_rejection(correction):
    """Whether a correction reports the verifier's rejection rather than an unread reply."""
    return correction.strip().lower().startswith(VERIFIER_HEADINGS)
