"""Draw the collapse mechanisms of the bundled walls (docs/img/la/<case>.png).

The core's ``mechanism`` plot of each la result: the deformed blocks coloured by macro-block (the
dominant ones numbered), cracked joints heavy, at the core's crack threshold. Run from the project
root: ``python docs/scripts/la_figures.py [--solver clarabel] [case ...]``.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import masonryfw as mf

OUT = Path(__file__).resolve().parents[1] / "img" / "la"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("cases", nargs="*", help="bundled case names (default: all)")
    parser.add_argument("--solver", default="clarabel")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for case in args.cases or list(mf.bundled_cases()):
        result = mf.solve(mf.open_model(case), "la", {"solver": args.solver})
        print(mf.save_figure(mf.render([result], "mechanism"), args.out / f"{case}.png", dpi=120))


if __name__ == "__main__":
    main()
