"""`python -m fabrication.cli` runs the onestroke command line."""

from fabrication.cli import main

main()
