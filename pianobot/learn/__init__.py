"""Learning: the two learners' loops, SAC (:mod:`~pianobot.learn.train`) and DAgger
(:mod:`~pianobot.learn.dagger`), and what they share (:mod:`~pianobot.learn.run`); their settings
(:mod:`~pianobot.learn.config`), exploration before learning (:mod:`~pianobot.learn.explore`) and
a whole piece's jobs (:mod:`~pianobot.learn.jobs`)."""
