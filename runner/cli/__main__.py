"""`python -m runner.cli ...`: the `scenario` command."""

from runner.cli import main

main()
