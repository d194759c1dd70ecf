"""``python -m benchmarks [--quick]``: regenerate benchmarks/RESULTS.md and its plots."""
import sys

from benchmarks.run import main

if __name__ == "__main__":  # not in the worker processes of `pipeline run --jobs N` (forkserver)
    sys.exit(main())
