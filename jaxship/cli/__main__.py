"""`python -m jaxship.cli`: the console script's entry (`_jaxship_cli.run`), so that
both forms end alike under Ctrl-C and SIGTERM at any moment (issue 72)."""

from _jaxship_cli import run


run()
