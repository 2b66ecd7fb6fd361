"""python3 -m caliper: the `caliper` command's create and measure, from Python."""
import sys

from ._cli import main

sys.exit(main(sys.argv[1:]))
