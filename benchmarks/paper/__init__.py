"""The paper's seven experiments (issue 21), each in two settings: the paper's recipe and ours;
and an eighth, which takes pianobot's additions away from its own setting one at a time.

    python -m benchmarks.paper EXPERIMENT [--setting paper|ours|both] [--seeds 3] [--steps N] [--workers 2]
    python -m benchmarks.paper EXPERIMENT --list       # the runs, how they differ, the CPU-hours they need
    python -m benchmarks.paper EXPERIMENT --report     # no training: tables and plots from the runs so far
    python -m benchmarks.paper EXPERIMENT --report --check   # and unfinished runs' best policies so far play

(from the repository root, where ``benchmarks`` is a package).

EXPERIMENT is a number or a name:

1 ``tasks``         one-note, three-note and six-note tasks; SAC with and without tactile images,
                    the scripted, idle and random controllers beside them (paper, figure "Comparison on
                    different levels of music tasks")
2 ``rhythm-chord``  the rhythmic and chord tasks (figure "Evaluation on tasks with different rhythms and chords")
3 ``rewards``       linear, squared and Wasserstein rewards (Table I)
4 ``exploration``   prior exploration, uniform moves of the hand, no action repeat (Table II)
5 ``control``       velocity against torque control (figure "Comparison of using torque control versus velocity control")
6 ``fingering``     with and without the fingering gate (figure "Qualitative results ... fingering indicators")
7 ``compose``       compositional execution against one end-to-end policy, pieces of growing length,
                    the same total steps (figure "Comparison between compositional execution ...")
8 ``additions``     not the paper's: pianobot's setting with one of its additions taken away at a
                    time (the teacher, the closeness bonus, the finger targets, its hyperparameters)
9 ``diagnosis``     not the paper's: why plain SAC learns nothing here; the paper setting on
                    one-note without touch, with one difference at a time (one joint per finger,
                    no fingering gate, the scripted pianist's exploration without its labels, our
                    hyperparameters), time-boxed with ``--stop-at``

Settings: ``paper`` is the paper's recipe: plain SAC (no teacher), prior exploration, the linear
reward without our closeness bonus, the score window as observation (no finger targets), the
learning rate 1e-3 and SAC's own values where the paper gives none (``experiments.setting_config``).
``ours`` is pianobot's defaults (:class:`~pianobot.learn.config.TrainConfig`). docs/paper.md
says what each choice rests on.

Every policy is trained by :func:`pianobot.learn.train.train_policy` (checkpointed: rerunning the
same command resumes every unfinished run), ``--workers`` at a time in worker processes with one
torch thread each. Runs with the same configuration (the paper setting's linear-reward,
velocity-control, gated run of experiments 3 to 6, say) share one model folder under
``--store`` and are trained once. Each kept policy is then evaluated with the paper's measure,
the accumulated *linear* reward (``experiments.EVAL_REWARD``), whatever reward it trained with, plus
note F1, velocity error and fingering accuracy, on ``--check-episodes`` task instances it was
never evaluated on (a piece from as many hand starts, for ``compose``). ``--report`` prints
Markdown tables (mean ± standard deviation over seeds) and draws return and note F1 against
environment steps (the training evaluations, in the reward each run trained with) into
``--plots`` (docs/paper/), from finished and unfinished runs alike. Beside each plot it keeps the
records of every run it has seen (``N-name.json``), and tables those of them the store lacks (a
fresh clone, another machine) from there.

The modules, in import order: ``experiments`` (the table of experiments and arms, the settings,
the options), ``runs`` (an experiment expanded into runs), ``evaluation`` (judging a run or a
baseline with the linear reward), ``training`` (training the runs' policies in worker
processes), ``records`` (what each run has so far, and ``N-name.json``), ``report`` (tables,
plots, ``--list``), ``cli`` (the command line; ``__main__`` runs it).
"""
