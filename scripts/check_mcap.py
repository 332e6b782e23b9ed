"""Third-party check of a Harvey recording: the Python `mcap` + `mcap-ros2-support` packages must
decode every message of every channel without Harvey's code.

Usage: check_mcap.py RUN.MCAP TOPIC...   (each TOPIC must hold at least one message)
"""
import sys
from collections import Counter

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def main() -> int:
    path, expected = sys.argv[1], sys.argv[2:]
    counts: Counter = Counter()
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        if header.profile != "ros2":
            print(f"{path}: profile is {header.profile!r}, not 'ros2'")
            return 1
        for schema, channel, message, decoded in reader.iter_decoded_messages():
            if decoded is None or schema.encoding != "ros2msg" or channel.message_encoding != "cdr":
                print(f"{path}: {channel.topic} message {message.sequence} not decoded as ros2msg/cdr")
                return 1
            counts[channel.topic] += 1
    missing = [t for t in expected if counts[t] == 0]
    for topic, n in sorted(counts.items()):
        print(f"  {topic:<22} {n:>7} messages decoded")
    if missing:
        print(f"{path}: no messages on {missing}")
    print(f"mcap-ros2-support decoded all {sum(counts.values())} messages on {len(counts)} channels")
    print(f"check_mcap: {len(expected) - len(missing)} passed, {len(missing)} failed")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
