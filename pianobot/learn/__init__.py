"""Learning: the training loop of one policy (:mod:`~pianobot.learn.train`), its settings
(:mod:`~pianobot.learn.config`), exploration before learning (:mod:`~pianobot.learn.explore`) and
a whole piece's jobs (:mod:`~pianobot.learn.jobs`)."""
