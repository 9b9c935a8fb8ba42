"""The ``masonryfw`` command (and ``python -m masonryfw``): Ctrl-C and SIGTERM answered from its first line.

The click layer's imports take about a second, numba's first compilation tens: the signal handlers are
installed before them (:func:`masonryfw.runtime.signals.install`), so a signal at any moment ends the command with
``128 + signal`` and one line. Only the interpreter's own start (some 20 ms) comes before.
"""
import sys

from masonryfw.runtime import signals


def main(argv: list[str] | None = None) -> None:
    signals.install()
    try:
        from masonryfw.cli import main as run
    except KeyboardInterrupt:
        print("interrupted while starting: nothing written", file=sys.stderr)
        sys.exit(signals.exit_status())
    try:
        run(argv)
    except SystemExit as end:
        signals.exiting(end.code if isinstance(end.code, int) else int(end.code is not None))
        raise


if __name__ == "__main__":
    try:
        main()
    finally:
        # Under ``python -m``, CPython ends the process by SIGINT (status -2, after our message and
        # sys.exit(130)) when a KeyboardInterrupt ended any string exec on the way, even one that was caught:
        # namedtuple and dataclass code is made that way while the modules load. A string exec that completes
        # clears that mark (Python/pythonrun.c, run_eval_code_obj), so the command's own status stands.
        exec("")
