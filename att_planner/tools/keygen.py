"""``att-keygen [--dir DIR] [--force]``: make the Ed25519 key pair that signs plans.

The planner signs every plan with the private key (its ``signing_key`` parameter) and the
controller flies only plans that verify against the public key (its ``plan_public_key``
parameter); both default to ``plan_signing.key`` / ``plan_signing.pub`` in
:func:`att_msgs_py.signing.default_key_dir` (``$ATT_KEY_DIR``, else ``<venv>/share/att_suite/keys``,
where ``make`` puts a pair for the demo). Copy only the ``.pub`` file to a controller's machine.
"""
from __future__ import annotations

import argparse
import sys

from att_msgs_py import signing


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="att-keygen", description=__doc__.splitlines()[0])
    parser.add_argument("--dir", default=None, help=f"where to write the pair (default {signing.default_key_dir()})")
    parser.add_argument("--force", action="store_true", help="replace an existing pair")
    parser.add_argument("--if-missing", action="store_true", help="do nothing when a pair is already there")
    args = parser.parse_args(argv)
    directory = signing.default_key_dir() if args.dir is None else args.dir
    try:
        private, public = signing.generate(directory, overwrite=args.force)
    except FileExistsError as err:
        if args.if_missing:
            return 0
        print(f"att-keygen: {err}", file=sys.stderr)
        return 1
    key = signing.load_private_key(private)
    print(f"att-keygen: private key {private} (keep it on the planner's machine), public key {public}, "
          f"key id {signing.key_id(key.public_key())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
