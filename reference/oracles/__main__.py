"""`python -m reference.oracles [--json]`: print the exact oracle table."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence

from reference.oracles.table import build_oracle_table, format_oracle_table, table_as_json_data


def main(argv: Sequence[str] | None = None) -> int:
    """Print the oracle table as text, or as JSON with `--json`."""
    parser = argparse.ArgumentParser(prog="python -m reference.oracles", description=__doc__)
    parser.add_argument("--json", action="store_true", help="print JSON instead of a text table")
    parser.add_argument("--gamma", type=float, default=0.6, help="discount of the optimal Q-table (0.6)")
    args = parser.parse_args(argv)
    table = build_oracle_table(gamma=args.gamma)
    print(json.dumps(table_as_json_data(table), indent=2) if args.json else format_oracle_table(table))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
