"""``python -m benchmarks.paper``: see the package's docstring, or ``--help``."""

from benchmarks.paper.cli import main

if __name__ == "__main__":
    main()
