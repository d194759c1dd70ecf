"""``python -m benchmarks [--quick]``: regenerate benchmarks/RESULTS.md and its plots."""
import sys

from benchmarks.run import main

sys.exit(main())
