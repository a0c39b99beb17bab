"""benchmarks/paper/ (``python -m benchmarks.paper``): the paper's experiments expand to the right runs, a run resumes, the report
tables mean ± std, and every policy is judged with the linear reward. One tiny training run
(300 steps, cut off at its first checkpoint and resumed) serves the slow tests."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
import torch

from benchmarks.paper import cli, evaluation, experiments, report, training
from benchmarks.paper.records import record_key
from benchmarks.paper.runs import expand
from pianobot.agent import store
from pianobot.agent.policy import load_policy
from pianobot.agent.tasks import make_env
from pianobot.env.rewards import RewardConfig
from pianobot.learn.config import TrainConfig
from pianobot.perform.rollout import rollout

torch.set_num_threads(1)

ALLOWED = {  # what the arms of an experiment may differ in, setting, task and seed alike
    "tasks": {"env.tactile"},
    "rhythm-chord": set(),
    "rewards": {"env.reward.kind"},
    "exploration": {"explore"},
    "control": {"env.world.control"},
    "fingering": {"env.reward.fingering_gate"},
}
TINY = ["--setting", "paper", "--seeds", "1", "--steps", "300", "--exploration-steps", "150"]
TINY += ["--eval-every", "100", "--eval-episodes", "1", "--check-episodes", "1"]


def options(tmp_path, **changes) -> experiments.Options:
    return replace(experiments.Options(store=tmp_path, seeds=2), **changes)


@pytest.mark.parametrize(
    "name, runs",
    [("tasks", 24), ("rhythm-chord", 8), ("rewards", 12), ("exploration", 14), ("control", 8), ("fingering", 8)],
)
def test_every_experiment_expands_to_its_arms_settings_tasks_and_seeds(tmp_path, name, runs):
    expanded = expand(name, options(tmp_path))
    assert len(expanded) == runs
    assert {r.setting for r in expanded} == {"paper", "ours"} and {r.seed for r in expanded} == {0, 1}
    assert expand(str(experiments.EXPERIMENTS[name].number), options(tmp_path)) == expanded  # 1-7 name them too
    groups: dict[tuple, list] = {}
    for run in expanded:
        assert len(run.jobs) == 1 and run.jobs[0].target == run.task  # one policy per run, on the task family
        groups.setdefault((run.setting, run.task, run.seed), []).append(run)
    for arms in groups.values():
        assert sorted(r.variant for r in arms) == sorted({r.variant for r in arms})  # each arm once
        for run in arms[1:]:
            assert set(report.differences(run.config, arms[0].config)) <= ALLOWED[name], (run.variant, name)


def test_the_tables_arms_are_the_papers():
    names = {e.name: [(v.name, v.paper_name) for v in e.variants] for e in experiments.EXPERIMENTS.values()}
    assert [n for n, _ in names["rewards"]] == ["linear", "squared", "wasserstein"]
    assert names["exploration"][:3] == [
        ("prior", "Prior Explore"),
        ("repeat", "Uniform Move Hand"),
        ("uniform", "No Action Repeat"),
    ]
    assert experiments.experiment_named("1").tasks == ("one-note", "three-note", "six-note")
    assert experiments.experiment_named("2").tasks == ("rhythmic", "chord")
    assert experiments.experiment_named("1").baselines == ("scripted", "idle", "random")
    assert all(e.baselines == experiments.BASELINES for e in experiments.EXPERIMENTS.values() if e.name != "compose")


def test_the_paper_setting_is_plain_sac_without_our_additions(tmp_path):
    for name in experiments.EXPERIMENTS:
        for run in expand(name, options(tmp_path, seeds=1, settings=("paper",))):
            config = run.config
            assert config.sac.demo_weight == 0  # no behaviour cloning
            assert config.explore != "scripted" or run.variant == "scripted-exploration"  # no teacher (but in that arm)
            assert config.env.reward.closeness_weight == 0  # no closeness bonus
            assert not config.env.target_observations and config.sac.score_input  # the paper's observation
            if run.variant != "our-hyperparameters":  # (the diagnosis's arm that tries ours)
                assert config.sac.learning_rate == 1e-3 and config.sac.initial_alpha == 0.02  # its hyperparameters
            assert config.sac.exploration_steps == 15_000


def test_the_ours_setting_is_pianobots_defaults_but_for_the_arm(tmp_path):
    for run in expand("rewards", options(tmp_path, seeds=1, settings=("ours",))):
        base = TrainConfig(steps=run.config.steps, eval_episodes=run.config.eval_episodes)
        assert set(report.differences(run.config, base)) <= {"env.reward.kind", "from_general"}
        assert not run.config.from_general  # from scratch: the general policy is not the paper's subject
    for run in expand("control", options(tmp_path, seeds=1, settings=("ours",))):
        assert run.config.explore == "prior"  # the scripted teacher has no torques: both arms explore alike


def test_steps_default_to_the_papers_budget_and_can_be_set(tmp_path):
    assert {r.config.steps for r in expand("tasks", options(tmp_path))} == {200_000}  # paper: 2e5
    assert {r.config.steps for r in expand("rewards", options(tmp_path))} == {experiments.ABLATION_STEPS}
    assert {r.config.steps for r in expand("rewards", options(tmp_path, steps=40_000))} == {40_000}
    _, parsed = cli.parse(["rewards", "--seeds", "5", "--setting", "paper", "--steps", "50000", "--tasks", "one-note"])
    runs = expand("rewards", parsed)
    assert len(runs) == 15 and {r.task for r in runs} == {"one-note"} and {r.seed for r in runs} == set(range(5))


def test_equal_configurations_share_one_folder_across_experiments(tmp_path):
    """The paper setting's linear / prior / velocity / gated run is one run in experiments 3-6."""
    folders = [
        next(r for r in expand(name, options(tmp_path, seeds=1, settings=("paper",))) if r.variant == arm)
        .jobs[0]
        .folder
        for name, arm in (
            ("rewards", "linear"),
            ("exploration", "prior"),
            ("control", "velocity"),
            ("fingering", "gate"),
        )
    ]
    assert len(set(folders)) == 1


def test_the_additions_experiment_takes_away_one_of_ours_at_a_time(tmp_path):
    """Experiment 8 is pianobot's setting only; each arm differs from it in one addition, and its
    full arm and its arm without the teacher are the runs experiments 3 and 4 already train."""
    runs = expand("additions", options(tmp_path, seeds=1))
    assert {r.setting for r in runs} == {"ours"} and {r.task for r in runs} == {"three-note"}
    arms = {r.variant: r for r in runs}
    removed = {
        "ours": set(),
        "no-teacher": {"explore"},
        "no-closeness": {"env.reward.closeness_weight"},
        "score-window": {"env.target_observations", "sac.score_input"},
        "paper-hyperparameters": {"sac.learning_rate", "sac.discount", "sac.target_entropy_scale"},
    }
    assert arms.keys() == removed.keys()
    for name, changed in removed.items():
        assert set(report.differences(arms[name].config, arms["ours"].config)) == changed, name
    paper_setting = experiments.setting_config("paper", options(tmp_path), 0, experiments.ABLATION_STEPS, 20)
    for name in ("no-closeness", "score-window", "paper-hyperparameters"):  # each takes the paper's value
        assert not removed[name] & report.differences(arms[name].config, paper_setting).keys(), name
    same_as = {"ours": ("rewards", "linear"), "no-teacher": ("exploration", "prior")}
    for name, (experiment, arm) in same_as.items():
        other = next(r for r in expand(experiment, options(tmp_path, seeds=1, settings=("ours",))) if r.variant == arm)
        assert other.jobs[0].folder == arms[name].jobs[0].folder
    assert expand("additions", options(tmp_path, seeds=1, settings=("paper",))) == []


def test_compose_trains_growing_pieces_end_to_end_with_the_same_total_steps(tmp_path):
    runs = expand("compose", options(tmp_path, steps=20_000))
    assert len(runs) == 2 * 2 * len(experiments.Options.lengths) * 2
    for setting in experiments.SETTINGS:
        for seed in (0, 1):
            mine = [r for r in runs if r.setting == setting and r.seed == seed]
            notes = []
            for composed, single in zip(mine[::2], mine[1::2]):
                assert (composed.variant, single.variant) == ("compositional", "end-to-end")
                assert composed.piece == single.piece
                assert len(single.jobs) == 1 and len(single.jobs[0].target) == len(single.piece)  # the whole piece
                assert all(len(job.target) <= 6 for job in composed.jobs)  # phrases
                assert composed.config.steps == 20_000
                assert single.config.steps == 20_000 * len(composed.jobs)  # the same total steps
                assert set(report.differences(single.config, composed.config)) <= {"steps"}  # nothing else
                notes.append(len(composed.piece))
            assert notes == sorted(notes) and len(set(notes)) == len(notes)  # growing pieces
            assert len({job.folder.parent for r in mine for job in r.jobs}) == 1  # shared phrases train once
    faster = expand("compose", options(tmp_path, steps=20_000, tempo=90.0))
    assert not {r.result for r in faster} & {r.result for r in runs}  # another tempo: judged afresh


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """The paper setting's squared-reward run of the rewards experiment, 300 steps: cut off after
    its first checkpoint, then rerun with the same command."""
    root = tmp_path_factory.mktemp("paper")
    args = [*TINY, "--store", str(root), "--plots", str(root / "plots"), "--variants", "squared"]
    _, opts = cli.parse(["rewards", *args])
    (run,) = expand("rewards", opts)
    assert run.variant == "squared" and run.config.env.reward.kind == "squared"
    cut = training.train_job(run.jobs[0], run.config, "tiny", stop_after=150)
    assert cut["state"] == "interrupted"
    return root, args, opts, run


def test_a_run_resumes_rather_than_restarts_when_rerun(tiny, capsys):
    root, args, opts, run = tiny
    folder = run.jobs[0].folder
    cut_at = store.checkpoint_state(folder)["step"]
    assert 150 <= cut_at < 300 and not store.is_trained(folder)

    cli.main(["rewards", *args, "--report", "--check"])  # an unfinished run is reported, its best policy judged
    printed = capsys.readouterr().out
    assert f"(at {cut_at} steps)" in printed and "| paper | three-note | squared | 1 / 0 / 1 / 1 |" in printed
    assert "- paper three-note squared: seed 0 " in printed and "(so far: best at " in printed  # provisional

    cli.main(["rewards", *args])
    printed = capsys.readouterr().out
    assert f"resuming from its checkpoint at step {cut_at}" in printed
    manifest = store.read_manifest(folder)
    assert manifest["steps"] == 300 and manifest["evaluations"][0]["step"] <= cut_at  # the evaluations before the cut

    cli.main(["rewards", *args])  # finished: nothing to train again
    assert "0 to train, 0 runs to evaluate" in capsys.readouterr().out


def test_report_tables_a_finished_run_with_mean_and_std(tiny, capsys):
    root, args, _, run = tiny
    if not store.is_trained(run.jobs[0].folder):
        cli.main(["rewards", *args])
        capsys.readouterr()
    cli.main(["rewards", *args, "linear", "--report"])  # --variants squared linear
    printed = capsys.readouterr().out
    row = next(line for line in printed.splitlines() if line.startswith("| paper | three-note | squared |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[3] == "1 / 1 / 1 / 1" and cells[4] == "300"
    assert " ± 0.00" in cells[5] and " ± 0.000" in cells[6]  # linear return and note F1, one seed
    f1 = cells[6].split(" ± ")[0]
    assert f"- paper three-note squared: seed 0 {f1}" in printed  # the seed behind the mean
    assert "| paper | three-note | linear | 0 / 0 / 0 / 1 |" in printed  # not started
    hours = store.read_manifest(run.jobs[0].folder)["seconds"] / 3600
    assert f"training so far: {hours:.1f} CPU-hours, 1 policy" in printed  # the squared run only
    assert (root / "plots" / "3-rewards.png").stat().st_size > 0


def test_a_report_keeps_records_beside_its_plot_and_tables_them_without_the_store(tiny, capsys, tmp_path):
    root, args, opts, run = tiny
    if not store.is_trained(run.jobs[0].folder):
        cli.main(["rewards", *args])
    key, path, png = record_key(run, opts), root / "plots" / "3-rewards.json", root / "plots" / "3-rewards.png"
    cli.main(["rewards", *args, "--report"])
    with_store = capsys.readouterr().out
    records = json.loads(path.read_text())["runs"]
    assert list(records) == [key] and records[key]["state"] == "finished" and records[key]["figures"]["episodes"] == 1

    def line(printed: str, start: str) -> str:
        return next(line for line in printed.splitlines() if line.startswith(start))

    elsewhere = [*args, "--store", str(tmp_path / "empty")]  # a fresh clone: no store, the records only
    png.unlink()
    cli.main(["rewards", *elsewhere, "--report"])
    without = capsys.readouterr().out
    row = line(without, "| paper | three-note | squared |")
    assert row == line(with_store, "| paper | three-note | squared |") and "1 / 1 / 1 / 1" in row  # the same figures
    assert line(without, "training so far") == line(with_store, "training so far") and "1 policy" in line(
        without, "training so far"
    )
    assert "not in the store" in without and "not in the store" not in with_store
    assert png.stat().st_size > 0  # drawn from the recorded curves

    stale = {**records[key], "state": "at 100 steps", "steps": 100, "figures": None}
    path.write_text(json.dumps({"runs": {key: stale}}))
    cli.main(["rewards", *args, "--report"])  # the store is further along than the record: it replaces it
    assert "| paper | three-note | squared | 1 / 1 / 1 / 1 |" in capsys.readouterr().out
    assert json.loads(path.read_text())["runs"] == records

    cli.main(["rewards", *args, "--report", "--check-episodes", "2"])  # judged on more episodes: recorded
    cli.main(["rewards", *args, "--report"])  # on fewer: the store's, but the record keeps the better judgement
    capsys.readouterr()
    assert json.loads(path.read_text())["runs"][key]["figures"]["episodes"] == 2
    cli.main(["rewards", *elsewhere, "--report"])  # judged otherwise than this report judges: no judgement
    assert "| paper | three-note | squared | 0 / 1 / 1 / 1 |" in capsys.readouterr().out

    so_far = {**stale, "figures": {**records[key]["figures"], "so_far": True, "kept_steps": [100]}}
    path.write_text(json.dumps({"runs": {key: so_far}}))  # an unfinished run's best policy so far
    cli.main(["rewards", *elsewhere, "--report"])
    assert "| paper | three-note | squared | 0 / 0 / 1 / 1 |" in capsys.readouterr().out  # only with --check
    cli.main(["rewards", *elsewhere, "--report", "--check"])
    assert "| paper | three-note | squared | 1 / 0 / 1 / 1 |" in capsys.readouterr().out

    conflicted = "<<<<<<< HEAD\n" + path.read_text()  # a merge left half done: not overwritten, one line
    path.write_text(conflicted)
    with pytest.raises(SystemExit) as stopped:
        cli.main(["rewards", *args])
    assert stopped.value.code == 2 and path.read_text() == conflicted
    assert capsys.readouterr().err.strip().startswith(f"error: {path} is not a records file")


def test_a_policy_trained_with_the_squared_reward_is_judged_with_the_linear_one(tiny, monkeypatch):
    root, args, opts, run = tiny
    folder = run.jobs[0].folder
    if not store.is_trained(folder):
        cli.main(["rewards", *args])
    built = []
    real = evaluation.make_env
    monkeypatch.setattr(evaluation, "make_env", lambda target, config: built.append(config) or real(target, config))
    figures = evaluation.evaluate_run(run, opts)
    assert built and all(c.reward == experiments.EVAL_REWARD for c in built)
    assert experiments.EVAL_REWARD.kind == "linear" and experiments.EVAL_REWARD.closeness_weight == 0
    assert figures["reward"]["kind"] == "linear" and figures["episodes"] == 1

    def played(reward: RewardConfig) -> float:
        env = make_env(run.task, replace(run.config.env, reward=reward))
        return rollout(env, load_policy(folder, env), seed=evaluation.CHECK_SEED).total_reward

    assert figures["return"] == pytest.approx(played(experiments.EVAL_REWARD))
    assert figures["return"] != pytest.approx(played(run.config.env.reward))  # the squared reward would differ


def test_cpu_hours_are_estimated_from_the_measured_training_speed(tmp_path):
    assert experiments.run_minutes(15_000, 15_000) == pytest.approx(4.0)
    assert experiments.run_minutes(40_000, 15_000) == pytest.approx(4.0 + 2.5 * 10.0)
    hours, policies = report.estimate(expand("rewards", options(tmp_path, seeds=3)))
    assert policies == 18 and hours == pytest.approx(18 * experiments.run_minutes(100_000, 15_000) / 60)


def test_stop_at_time_boxes_every_run_at_a_checkpoint_and_the_full_command_goes_on(tmp_path, capsys, monkeypatch):
    args = [*TINY, "--store", str(tmp_path), "--plots", str(tmp_path / "plots"), "--variants", "linear"]
    with pytest.raises(SystemExit):  # between checkpoints the steps after the last one would be lost
        cli.parse(["rewards", *args, "--stop-at", "250"])
    _, opts = cli.parse(["rewards", *args, "--stop-at", "200"])
    (run,) = expand("rewards", opts)
    assert opts.stop_at == 200 and run.config.steps == 300  # the protocol's budget, not the time box
    assert not run.config.from_general and run.config.stop_f1 is None  # trains from scratch, never stops early

    cli.main(["rewards", *args, "--stop-at", "200"])
    folder = run.jobs[0].folder
    stopped = store.checkpoint_state(folder)["step"]
    assert 200 <= stopped < 300 and not store.is_trained(folder)
    assert "stopped at step" in capsys.readouterr().out

    played, real = [], evaluation.play_instances  # --report --check judges the best so far once, then reads it back
    monkeypatch.setattr(evaluation, "play_instances", lambda *a: played.append(a[3]) or real(*a))
    judged = evaluation.best_so_far(run, opts)
    assert judged["so_far"] and evaluation.best_so_far(run, opts) == judged and played == [1]
    assert evaluation.best_so_far(run, replace(opts, check_episodes=2))["episodes"] == 2 and played == [1, 2]
    cached = tmp_path / experiments.SO_FAR_DIR / f"{folder.name}.json"
    assert not list(folder.glob("*.json*"))  # nothing written into the folder its training owns
    stale = json.loads(cached.read_text())  # a folder trained afresh: its best falls on the same step
    stale["best"] = {**stale["best"], "f1": stale["best"]["f1"] + 0.5}
    cached.write_text(json.dumps(stale))
    assert evaluation.best_so_far(run, replace(opts, check_episodes=2))["best"] != stale["best"] and played == [1, 2, 2]

    cli.main(["rewards", *args, "--stop-at", "200"])  # already there: nothing is trained again
    assert "already past --stop-at 200" in capsys.readouterr().out
    assert store.checkpoint_state(folder)["step"] == stopped

    cli.main(["rewards", *args])  # without it: on to the full budget
    assert f"resuming from its checkpoint at step {stopped}" in capsys.readouterr().out
    assert store.read_manifest(folder)["steps"] == 300


def test_the_idle_hand_presses_no_key_and_earns_between_random_and_scripted(tmp_path):
    opts = options(tmp_path, check_episodes=2)
    played = {c: evaluation.baseline_figures(c, "three-note", 0, opts) for c in experiments.BASELINES}
    assert played["idle"]["f1"] == 0 and played["idle"]["velocity_mae"] is None  # no note sounded
    assert played["random"]["return"] < played["idle"]["return"] < played["scripted"]["return"]
    assert played["scripted"]["f1"] == 1.0
    assert evaluation.baseline_figures("idle", "three-note", 0, opts) == played["idle"]  # cached


def test_the_diagnosis_changes_one_thing_at_a_time_in_the_paper_setting(tmp_path):
    """Experiment 9 is the paper setting on one-note without touch; its `paper` arm is experiment 1's
    run (one folder), and each other arm differs from it in exactly the fields named."""
    runs = expand("diagnosis", options(tmp_path, seeds=1))
    assert {r.setting for r in runs} == {"paper"} and {r.task for r in runs} == {"one-note"}
    arms = {r.variant: r for r in runs}
    changed = {
        "paper": set(),
        "one-joint": {"env.actuated"},
        "no-gate": {"env.reward.fingering_gate"},
        "scripted-exploration": {"explore"},
        "our-hyperparameters": {"sac.learning_rate", "sac.discount", "sac.target_entropy_scale"},
    }
    assert arms.keys() == changed.keys()
    for name, fields in changed.items():
        assert set(report.differences(arms[name].config, arms["paper"].config)) == fields, name
    assert arms["one-joint"].config.env.actuated == ("mcp",)  # the paper's one action per finger
    assert arms["scripted-exploration"].config.sac.demo_weight == 0  # the teacher explores, no cloning
    tasks = expand("tasks", options(tmp_path, seeds=1, settings=("paper",)))
    without_touch = next(r for r in tasks if r.task == "one-note" and r.variant == "no-tactile")
    assert arms["paper"].jobs[0].folder == without_touch.jobs[0].folder
