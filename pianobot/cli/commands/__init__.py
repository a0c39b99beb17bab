"""One module per command; :mod:`pianobot.cli.app` registers them."""
