"""Classify a Lab Streaming Layer (LSL) stream live with a neurotex model, in Python.

    python lsl_classify.py --model model.json --stream Fingertip [--publish Decisions]

Finds the LSL stream named ``--stream`` (one numeric channel per taxel of the model), feeds
each sample to ``neurotex.StreamClassifier`` with its LSL time stamp, prints each decision
as a JSON line, and publishes it on an LSL marker stream when ``--publish`` names one. It
ends when the stream goes away. The command line does the same:

    neurotex stream --model model.json --input lsl:Fingertip --publish lsl:Decisions

Needs ``pip install pylsl`` (its wheel bundles liblsl).
"""

import argparse
import json
from typing import Any, Dict, List, Optional

import pylsl

try:
    from pylsl.util import LostError
except ImportError:  # pylsl before 1.17
    from pylsl import LostError

import neurotex


def classify(model: str, stream: str, publish: Optional[str] = None,
             timeout: float = 10.0) -> List[Dict[str, Any]]:
    """Classifies the LSL stream named ``stream`` until it goes away; the decision lines."""
    found = pylsl.resolve_byprop("name", stream, timeout=timeout)
    if not found:
        raise SystemExit(f"no LSL stream named {stream!r} within {timeout} s")
    # recover=False: a stream that goes away ends the loop instead of being waited for.
    inlet = pylsl.StreamInlet(found[0], recover=False)
    classifier = neurotex.StreamClassifier(model, time_unit="s")
    outlet = None
    if publish:
        info = pylsl.StreamInfo(publish, "Markers", 1, pylsl.IRREGULAR_RATE, "string",
                                f"neurotex-{publish}")
        outlet = pylsl.StreamOutlet(info)
    lines: List[Dict[str, Any]] = []

    def say(events: Optional[List[Dict[str, Any]]]) -> None:
        for event in events or []:
            line = json.dumps(event, sort_keys=True)
            print(line, flush=True)
            lines.append(event)
            if outlet is not None:
                outlet.push_sample([line])

    while True:
        try:
            frames, stamps = inlet.pull_chunk(timeout=0.1)
        except LostError:
            break
        for frame, t in zip(frames, stamps):
            try:
                say(classifier.push(frame, t))
            except neurotex.DataError as e:  # a bad frame is skipped; the stream goes on
                print(f"bad frame skipped: {e}")
    say(classifier.finish())
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--model", required=True, help="a model trained with --causal")
    parser.add_argument("--stream", required=True, help="the LSL stream's name")
    parser.add_argument("--publish", help="an LSL marker stream to publish decisions on")
    parser.add_argument("--timeout", type=float, default=10.0,
                        help="how long to look for the stream, s")
    args = parser.parse_args()
    classify(args.model, args.stream, args.publish, args.timeout)


if __name__ == "__main__":
    main()
