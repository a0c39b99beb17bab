"""The ``pianobot`` command line (:mod:`~pianobot.cli.app`) and its terminal tables (:mod:`~pianobot.cli.display`)."""
