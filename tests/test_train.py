"""Training: real gradient updates with finite losses, save/load, exact resume, skip-if-trained."""

import itertools
import json
from dataclasses import replace

import numpy as np
import pytest
import torch

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.agent.policy import load_policy, make_agent
from pianobot.env.piano import EnvConfig
from pianobot.errors import PianobotError
from pianobot.learn.config import TrainConfig
from pianobot.learn.explore import Explorer
from pianobot.learn.jobs import PhraseJob, phrase_jobs, plan_jobs
from pianobot.learn.log import LOG_FILE, PLOT_FILE, TENSORBOARD_DIR
from pianobot.learn.train import Progress, make_env, train_policy
from pianobot.music.phrases import split_phrases
from pianobot.music.piece import Note, Piece
from pianobot.perform.rollout import rollout

PHRASE = Piece((Note(0.0, 64, 0.5, 80, 3),), bpm=60)  # a one-note phrase: 35 steps an episode


def small(**changes) -> TrainConfig:
    sac = SACConfig(exploration_steps=60, batch_size=32, buffer_size=1000, hidden=32, score_features=16)
    config = TrainConfig(
        steps=200, eval_every=10_000, eval_episodes=1, checkpoint_every=70, sac=sac, env=EnvConfig(tactile=True)
    )
    return replace(config, **changes)


def test_training_runs_real_updates_with_finite_losses(tmp_path):
    seen: list[Progress] = []
    manifest = train_policy(PHRASE, small(), tmp_path / "m", seen.append, about={"key": "k", "piece": "p"})
    assert manifest["steps"] == 200 and manifest["updates"] == 140  # one update per step after exploration
    assert seen[-1].finished and seen[-1].step == 200 and sum(p.finished for p in seen) == 1  # the bar ends full
    losses = [p.losses for p in seen if p.losses]
    assert losses and all(np.isfinite(v) for step in losses for v in step.values())
    assert 0.0 <= manifest["evaluation"]["f1"] <= 1.0 and manifest["key"] == "k"
    assert store.is_trained(tmp_path / "m") and not (tmp_path / "m" / store.CHECKPOINT_DIR).exists()
    stored = json.loads((tmp_path / "m" / store.MANIFEST_FILE).read_text())
    assert stored["format"] == store.FORMAT and "torch" in stored["versions"] and stored["config"]["steps"] == 200


def test_saved_policy_loads_and_acts_the_same(tmp_path):
    config = small()
    train_policy(PHRASE, config, tmp_path / "m")
    env = make_env(PHRASE, config.env)
    observation, _ = env.reset(seed=0)
    first_agent, second_agent = load_policy(tmp_path / "m", env), load_policy(tmp_path / "m", env)
    first, second = first_agent.act(observation), second_agent.act(observation)
    assert first.shape == (13,) and np.array_equal(first, second)
    tensors = store.load_tensors(tmp_path / "m" / store.POLICY_FILE)
    assert not any(k.startswith(("critic.", "target.", "optim.")) for k in tensors)  # only what acting needs
    assert not any(".conv." in k for k in tensors)  # the tactile convolutions once, under encoder.tactile.0
    critic = store.load_tensors(tmp_path / "m" / store.CRITIC_FILE)  # beside it: what fine-tuning starts from
    assert set(critic) == {"log_alpha"} | {k for k in first_agent.critic_tensors() if k.startswith("critic.layers.")}


def test_finish_stores_an_interrupted_sac_runs_checkpointed_policy_evaluated(tmp_path):
    """`train --finish` on a SAC run cut after its checkpoint at step 70 (no evaluation yet): no step
    more; the checkpoint's policy is evaluated and stored, the manifest saying 70 steps."""
    torch.set_num_threads(1)
    config = small()
    folder = tmp_path / "m"
    assert train_policy(PHRASE, config, folder, stop_after=100) == {"interrupted_at": 105}
    tensors, _, _ = store.load_checkpoint(folder)
    manifest = train_policy(PHRASE, replace(config, finish=True), folder)
    assert manifest["steps"] == 70 and manifest["evaluation"]["step"] == 70 and len(manifest["evaluations"]) == 1
    stored = store.load_tensors(folder / store.POLICY_FILE)
    assert all(torch.equal(stored[k], tensors[k]) for k in stored)  # the checkpoint's actor, not trained further
    assert not (folder / store.CHECKPOINT_DIR).exists()
    # cut at a checkpoint before the first learning step (still exploring): nothing learnt to keep, it trains on
    exploring = small(sac=replace(small().sac, exploration_steps=150))
    assert train_policy(PHRASE, exploring, tmp_path / "e", stop_after=100) == {"interrupted_at": 105}
    assert train_policy(PHRASE, replace(exploring, finish=True), tmp_path / "e")["steps"] >= exploring.steps


def test_interrupted_training_resumes_to_the_same_state(tmp_path):
    torch.set_num_threads(1)
    config = small()
    straight = tmp_path / "straight"
    train_policy(PHRASE, config, straight)
    resumed = tmp_path / "resumed"
    assert train_policy(PHRASE, config, resumed, stop_after=100) == {"interrupted_at": 105}
    assert store.checkpoint_state(resumed)["step"] == 70 and not store.is_trained(resumed)
    (state_file,) = (resumed / store.CHECKPOINT_DIR).glob("*/state.json")
    state = json.loads(state_file.read_text())
    state["env_rng"] = state["env_rng"][0]  # as checkpoints from before --envs held it: they resume exactly too
    state_file.write_text(json.dumps(state))
    train_policy(PHRASE, config, resumed)
    a = store.load_tensors(straight / store.POLICY_FILE)
    b = store.load_tensors(resumed / store.POLICY_FILE)
    assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)
    assert (
        json.loads((straight / "manifest.json").read_text())["evaluation"]
        == json.loads((resumed / "manifest.json").read_text())["evaluation"]
    )


def test_skip_if_trained_and_identical_phrases_share_a_policy(tmp_path):
    config = small()
    repeated = Piece(PHRASE.notes + PHRASE.shift(2.0).notes + (Note(4.0, 67, 4.5, 90, 4),), bpm=60)
    phrases = split_phrases(repeated, 1)
    todo, done = plan_jobs(phrase_jobs(phrases, config, tmp_path), force=False)
    assert [j.phrases for j in todo] == [[0, 1], [2]] and done == []
    train_policy(todo[0].target, config, todo[0].folder)
    todo, done = plan_jobs(phrase_jobs(phrases, config, tmp_path), force=False)
    assert [j.phrases for j in done] == [[0, 1]] and [j.phrases for j in todo] == [[2]]
    todo, done = plan_jobs(phrase_jobs(phrases, config, tmp_path), force=True)
    assert len(todo) == 2 and done == []
    other = plan_jobs(phrase_jobs(phrases, replace(config, seed=1), tmp_path), force=False)[0]
    assert len(other) == 2  # another configuration is another model


def test_a_forced_run_keeps_the_old_policy_playing_until_its_own_is_stored(tmp_path):
    """A forced run that is interrupted leaves what was stored (the piece plays as before it), and the
    next run, plain or forced, goes on with it from its checkpoint; the same forced run given again
    after an interruption trains only the phrases it had not finished, and a forced run of other
    phrases, or one after the command has judged the piece, trains every phrase anew."""
    from pianobot.learn import forced
    from pianobot.learn.forced import forced_run
    from pianobot.learn.jobs import task_job

    def planned(jobs, force):
        return plan_jobs(jobs, force, *forced_run([job.folder for job in jobs]))

    config = small(steps=80, checkpoint_every=40)
    job = task_job("one-note", config, tmp_path)
    train_policy(job.target, config, job.folder)
    old = (job.folder / store.POLICY_FILE).read_bytes()
    store.mark_general_plays(tmp_path, {job.folder.name: {"why": "set aside"}})  # (as a piece's judgement does)
    assert planned([job], False) == ([], [job])
    assert planned([job], True) == ([job], []) and store.is_trained(job.folder)
    assert job.folder.name in store.general_plays(tmp_path)  # set aside it stays, while it is trained anew
    store.mark_general_plays(tmp_path, {job.folder.name: None})
    train_policy(job.target, config, job.folder, stop_after=40)  # the forced run is interrupted
    assert (job.folder / store.POLICY_FILE).read_bytes() == old and not forced.replacing(job.folder)["finished"]
    assert planned([job], False) == ([job], [])  # the next plain run goes on with it
    assert planned([job], True) == ([job], [])
    manifest = job.folder / store.MANIFEST_FILE
    manifest.write_text(json.dumps({**json.loads(manifest.read_text()), "the old one": True}))
    train_policy(job.target, config, job.folder)  # from its checkpoint, to the end
    assert forced.replacing(job.folder)["finished"] and store.is_trained(job.folder)
    assert "the old one" not in store.read_manifest(job.folder)  # the new run's manifest
    assert not (job.folder / store.CHECKPOINT_DIR).exists()
    assert planned([job], True) == ([], [job])  # the interrupted command, given again, goes on
    assert planned([job], False) == ([], [job])

    other = task_job("three-note", config, tmp_path)
    train_policy(other.target, config, other.folder)
    assert planned([job, other], True) == ([job, other], [])  # another forced run: both anew
    forced.replaced(job.folder, policy_kept=True)  # the first finished, then the run was interrupted
    assert planned([job, other], True) == ([other], [job])  # the same command goes on
    assert planned([other], True) == ([other], [])  # a forced run of other phrases: anew
    forced.replaced(other.folder, policy_kept=False)  # finished, keeping its start: the old policy goes
    assert not (other.folder / store.POLICY_FILE).exists()
    for folder in (job.folder, other.folder):
        forced.forget_replacing(folder)  # the command judged the piece
    assert planned([job, other], True) == ([job, other], [])  # a new forced run: all again


def test_corrupt_and_foreign_model_files_are_clear_errors(tmp_path):
    folder = tmp_path / "m"
    folder.mkdir()
    (folder / store.POLICY_FILE).write_bytes(b"not safetensors")
    with pytest.raises(PianobotError, match="not a readable safetensors"):
        store.load_tensors(folder / store.POLICY_FILE)
    with pytest.raises(PianobotError, match="holds no manifest.json"):
        store.read_manifest(folder)
    (folder / store.MANIFEST_FILE).write_text('{"weights": [1, 2]}')
    with pytest.raises(PianobotError, match="not a pianobot model manifest"):
        store.read_manifest(folder)
    (folder / store.MANIFEST_FILE).write_text("{oops")
    with pytest.raises(PianobotError, match="not a readable manifest"):
        store.read_manifest(folder)


def test_policy_of_another_shape_is_refused(tmp_path):
    config = small()
    train_policy(PHRASE, config, tmp_path / "m")
    manifest = json.loads((tmp_path / "m" / store.MANIFEST_FILE).read_text())
    manifest["config"]["sac"]["hidden"] = 64
    (tmp_path / "m" / store.MANIFEST_FILE).write_text(json.dumps(manifest))
    env = make_env(PHRASE, config.env)
    with pytest.raises(PianobotError, match=r"tensor actor\.net\.0\.bias has shape \(32,\), this agent's is \(64,\)"):
        load_policy(tmp_path / "m", env)


def test_policy_with_bad_values_is_refused(tmp_path):
    config = small(env=EnvConfig(tactile=False))
    train_policy(PHRASE, config, tmp_path / "m")
    env = make_env(PHRASE, config.env)
    tensors = store.load_tensors(tmp_path / "m" / store.POLICY_FILE)
    name = "actor.net.2.bias"
    for bad, message in ((tensors[name].fill_(float("nan")), "NaN"), (tensors[name].to(torch.int64), "torch.int64")):
        store.save_tensors({**tensors, name: bad}, tmp_path / "m" / store.POLICY_FILE)
        with pytest.raises(PianobotError, match=f"tensor {name}.*{message}"):
            load_policy(tmp_path / "m", env)


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("hidden", "256", "expected a whole number, got str '256'"),
        ("hidden", 2_000_000, "hidden 2000000 must be between 1 and 4096"),
        ("hidden", -5, "hidden -5 must be between 1 and 4096"),
        ("discount", float("nan"), "expected a finite number"),
        ("colour", 1, "not a field of SACConfig"),
    ],
)
def test_manifest_values_that_do_not_fit_are_one_line_errors(tmp_path, field, value, message):
    config = small(env=EnvConfig(tactile=False))
    train_policy(PHRASE, config, tmp_path / "m")
    manifest = json.loads((tmp_path / "m" / store.MANIFEST_FILE).read_text())
    manifest["config"]["sac"][field] = value
    (tmp_path / "m" / store.MANIFEST_FILE).write_text(json.dumps(manifest))
    with pytest.raises(PianobotError, match=f"config\\.sac.*{message}") as error:
        load_policy(tmp_path / "m", make_env(PHRASE, config.env))
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("kind", ["uniform", "repeat", "prior", "scripted"])
def test_exploration_strategies(kind):
    env = make_env(PHRASE, EnvConfig(tactile=False))
    observation, _ = env.reset(seed=0)
    explorer = Explorer(kind, 13, env.config, np.random.default_rng(0))
    explorer.reset()  # as training does at every episode's start: draws the episode's noise
    actions, teacher = [], []
    for _ in range(300):
        taught = explorer.teach(observation)
        action = explorer.act(observation, taught)
        actions.append(action)
        teacher.append(taught if taught is not None else np.zeros(13))
        observation, _, _, truncated, _ = env.step(action)
        if truncated:
            observation, _ = env.reset()
            explorer.reset()
    actions = np.array(actions)
    repeats = np.mean([np.array_equal(a[:-1], b[:-1]) for a, b in zip(actions, actions[1:])])
    wrist_moves = np.mean(actions[:, -1] != 0)
    if kind == "uniform":
        assert repeats == 0 and wrist_moves == 1
    if kind == "repeat":
        assert 0.7 < repeats < 0.9
    if kind == "prior":
        assert 0.7 < repeats < 0.9 and wrist_moves < 0.2
    if kind == "scripted":  # the teacher's action plus a little noise: it follows the teacher
        assert np.abs(actions - teacher).mean() < 0.2 and repeats == 0


def test_an_agent_that_does_not_read_the_score_window_does_not_store_it(tmp_path):
    """The window is 1320 floats of a 1400-float vector: without score input, neither the agent
    nor its replay buffer carries it."""
    from pianobot.agent.sac import score_size, vector_size

    env = make_env(PHRASE, EnvConfig(tactile=False))
    space = env.observation_space
    observation, _ = env.reset(seed=0)
    for reads in (False, True):
        agent = make_agent(env, replace(small().sac, score_input=reads))
        vector, _ = agent.split(observation)
        assert vector.size == vector_size(space, reads) == vector_size(space) - (0 if reads else score_size(space))
        assert agent.sample(vector, None).shape == agent.act(observation).shape == (13,)
    manifest = train_policy(
        PHRASE, small(env=EnvConfig(tactile=False), steps=80, checkpoint_every=40), tmp_path / "m", stop_after=45
    )
    assert "interrupted_at" in manifest  # (at the first episode end after 45 steps)
    stored = np.load(next((tmp_path / "m" / store.CHECKPOINT_DIR).rglob("*vector*.npy")), mmap_mode="r")
    assert stored.shape[-1] == vector_size(space, False)


def test_scripted_exploration_mixes_quiet_episodes_that_play_with_noisy_ones():
    """A strike fails with noise much above 0.02: the noise scale is drawn per episode, so the
    buffer gets episodes that play the note (a fixed 0.2 played none) and ones that go astray."""
    env = make_env(PHRASE, EnvConfig(tactile=False))
    explorer = Explorer("scripted", env.action_space.shape[0], env.config, np.random.default_rng(0))
    noises, f1s = [], []
    for episode in range(10):
        f1s.append(rollout(env, explorer, seed=episode).report().f1)  # rollout resets the explorer
        noises.append(explorer.noise)
    noises, f1s = np.array(noises), np.array(f1s)
    assert np.all((0.005 <= noises) & (noises <= 0.2)) and noises.min() < 0.02 and noises.max() > 0.05
    assert np.all(f1s[noises < 0.02] == 1.0)


def _agent_and_batch(demo_weight: float, demo: float):
    from pianobot.agent.sac import SAC

    torch.manual_seed(0)
    env = make_env(PHRASE, EnvConfig(tactile=False))
    config = SACConfig(
        batch_size=64, hidden=32, score_features=16, demo_weight=demo_weight, learning_rate=1e-3
    )  # the mechanism, quickly
    from pianobot.agent.sac import score_size, vector_size

    space, score = env.observation_space, config.score_input
    agent = SAC(vector_size(space, score), score_size(space, score), None, env.action_space.shape[0], config)
    rng = np.random.default_rng(0)
    n, dim = 64, vector_size(space, score)
    target = np.tile(np.linspace(-0.6, 0.6, env.action_space.shape[0], dtype=np.float32), (n, 1))
    batch = {
        "vector": torch.from_numpy(rng.normal(size=(n, dim)).astype(np.float32)),
        "next_vector": torch.from_numpy(rng.normal(size=(n, dim)).astype(np.float32)),
        "action": torch.from_numpy(target),
        "reward": torch.zeros(n),
        "terminated": torch.zeros(n),
        "demo": torch.full((n,), demo),
        "expert": torch.from_numpy(target),
        "tactile": None,
        "next_tactile": None,
    }
    return agent, batch, target


def test_behaviour_cloning_pulls_the_actor_towards_demonstrations():
    """With demonstrations in the batch the actor's mean action moves to the demonstrated one;
    without (demo flags 0, or demo_weight 0) it does not."""

    def error_after_updates(demo_weight, demo):
        agent, batch, target = _agent_and_batch(demo_weight, demo)
        for _ in range(150):
            agent.update(batch)
        with torch.no_grad():
            mean = agent.actor.deterministic(agent.critic.encoder(batch["vector"], None), batch["vector"])
        return float((mean.numpy() - target).__abs__().mean())

    cloned, unflagged, off = error_after_updates(1.0, 1.0), error_after_updates(1.0, 0.0), error_after_updates(0.0, 1.0)
    assert cloned < 0.1  # measured 0.07 against 0.20 for both others
    assert unflagged > 2 * cloned and off > 2 * cloned


def test_until_f1_stops_at_the_first_good_evaluation(tmp_path, monkeypatch):
    import pianobot.learn.train as train

    calls = []

    def perfect(agent, target, env_config, episodes):
        calls.append(agent.updates)
        return {"f1": 1.0, "velocity_mae": 0.0, "return": 1.0}

    monkeypatch.setattr(train, "evaluate", perfect)
    config = small(steps=400, eval_every=100, until_f1=0.95)
    manifest = train_policy(PHRASE, config, tmp_path / "m")
    assert manifest["steps"] < 200 and len(calls) == 1  # stopped at the first evaluation, not evaluated twice
    assert manifest["evaluation"]["f1"] == 1.0 and store.is_trained(tmp_path / "m")
    whole = train_policy(PHRASE, replace(config, until_f1=None), tmp_path / "n")
    assert whole["steps"] == 400


def test_fine_tuning_never_ends_worse_than_its_start_policy(tmp_path, monkeypatch):
    """The start policy's evaluation at step 0 counts: when no later one beats it, nothing is
    stored (the start plays best); a later better one is stored, policy and critic."""
    import pianobot.learn.train as train

    def scripted(scores, calls):
        figures = iter(scores)

        def evaluate(agent, target, env_config, episodes):
            calls.append(agent.updates)
            return {"f1": next(figures), "velocity_mae": 1.0, "return": 0.0}

        return evaluate

    config = small(steps=200, eval_every=100)
    train_policy(PHRASE, config, tmp_path / "start")
    start = {**store.load_tensors(tmp_path / "start" / store.POLICY_FILE)}
    start.update(store.load_tensors(tmp_path / "start" / store.CRITIC_FILE))
    for scores, kept_step in (([0.5, 0.4, 0.2], 0), ([0.5, 0.6, 0.2], 105)):
        calls: list = []
        monkeypatch.setattr(train, "evaluate", scripted(scores, calls))
        folder = tmp_path / f"tuned-{kept_step}"
        manifest = train_policy(PHRASE, replace(config, finetune_until_f1=0.99), folder, start=tmp_path / "start")
        assert (
            calls[0] == 0 and len(calls) == 3
        )  # the start, before any update; one during training (at an episode end); the final
        assert [e["step"] for e in manifest["evaluations"]] == [0, 105, 200]
        assert manifest["evaluation"]["step"] == kept_step and manifest["steps"] == 200
        assert manifest["kept"] == ("start" if kept_step == 0 else "trained")
        if kept_step == 0:
            assert not store.is_trained(folder)
            continue
        kept = {**store.load_tensors(folder / store.POLICY_FILE), **store.load_tensors(folder / store.CRITIC_FILE)}
        assert set(kept) == set(start) and not all(torch.equal(kept[k], start[k]) for k in start)


def test_a_start_policy_that_already_plays_the_phrase_stores_nothing(tmp_path, monkeypatch):
    """Fine-tuning whose step-0 evaluation reaches stop_f1 stores no copy of the start policy: the
    run removes its log and its folder (or, in a folder that holds other files, only what it
    wrote) and returns the manifest, which says ``kept: start``; a run that stores its policy
    says ``kept: trained``. Both learners."""
    import pianobot.learn.dagger as dagger
    import pianobot.learn.train as train

    config = small(steps=80)
    assert train_policy(PHRASE, config, tmp_path / "start")["kept"] == "trained"
    assert store.read_manifest(tmp_path / "start")["kept"] == "trained"
    perfect = {"f1": 1.0, "velocity_mae": 0.0, "return": 1.0}
    for module in (train, dagger):
        monkeypatch.setattr(module, "evaluate", lambda *a: dict(perfect))
    tuned = replace(config, from_general=True)
    for learn, learner in ((train_policy, "sac"), (dagger.dagger_policy, "dagger")):
        seen: list[Progress] = []
        folder = tmp_path / f"tuned-{learner}"
        manifest = learn(
            PHRASE, replace(tuned, learner=learner), folder, seen.append, about={"key": "k"}, start=tmp_path / "start"
        )
        assert manifest["kept"] == "start" and manifest["key"] == "k"
        assert manifest["steps"] == 0 and manifest["updates"] == 0
        assert manifest["evaluations"] == [manifest["evaluation"]] == [{"step": 0, **perfect}]
        assert manifest["start"]["path"] == str(tmp_path / "start") and manifest["config"]["from_general"] is True
        assert not folder.exists()  # no policy, no log, no folder
        assert seen[-1].finished and seen[-1].step == 0

    kept = tmp_path / "kept"  # a folder with a file of its own keeps it, and only it
    kept.mkdir()
    (kept / "notes.txt").write_text("mine")
    assert train_policy(PHRASE, tuned, kept, start=tmp_path / "start")["kept"] == "start"
    assert sorted(p.name for p in kept.iterdir() if p.name != store.LOCK_FILE) == ["notes.txt"]


def test_a_run_that_never_beats_its_start_stores_no_copy_of_it_and_keeps_its_log(tmp_path, monkeypatch):
    """Training from a start policy whose step-0 evaluation no later one beats stores nothing
    (the store would hold a copy of the start as a policy of its own): ``kept: start`` with the
    steps trained, the log and its curves kept, the checkpoint gone. Both learners."""
    import pianobot.learn.dagger as dagger
    import pianobot.learn.train as train
    from pianobot.learn import forced

    config = small(steps=80)
    train_policy(PHRASE, config, tmp_path / "start")
    tuned = replace(config, from_general=True, steps=200, eval_every=100)
    for learn, learner, module in ((train_policy, "sac", train), (dagger.dagger_policy, "dagger", dagger)):
        scores = itertools.chain([0.8, 0.5], itertools.repeat(0.7))  # the start's (step 0), then worse ones
        monkeypatch.setattr(
            module, "evaluate", lambda *a, scores=scores: {"f1": next(scores), "velocity_mae": 1.0, "return": 0.0}
        )
        folder = tmp_path / f"tuned-{learner}"
        run = replace(tuned, learner=learner, dagger=replace(tuned.dagger, round_steps=100))
        manifest = learn(PHRASE, run, folder, start=tmp_path / "start")
        assert manifest["kept"] == "start" and manifest["steps"] >= 200
        assert manifest["evaluation"]["step"] == 0 and manifest["evaluation"]["f1"] == 0.8
        assert len(manifest["evaluations"]) >= 3 and max(e["f1"] for e in manifest["evaluations"][1:]) < 0.8
        assert not store.is_trained(folder) and not (folder / store.POLICY_FILE).exists()
        assert store.kept_start(folder) and store.read_manifest(folder)["kept"] == "start"  # the run is done
        assert (folder / LOG_FILE).exists() and (folder / PLOT_FILE).exists() and store.load_checkpoint(folder) is None
        job = PhraseJob("k", PHRASE, folder, [0])
        assert plan_jobs([job], force=False) == ([], [job])  # a second `train` skips it
        assert plan_jobs([job], force=True) == ([job], []) and forced.replacing(folder) is not None  # --force: anew
    # a run that does beat its start stores its policy
    scores = itertools.chain([0.5, 0.9], itertools.repeat(0.6))
    monkeypatch.setattr(train, "evaluate", lambda *a: {"f1": next(scores), "velocity_mae": 1.0, "return": 0.0})
    manifest = train_policy(PHRASE, tuned, tmp_path / "better", start=tmp_path / "start")
    assert manifest["kept"] == "trained" and manifest["evaluation"]["step"] == manifest["evaluations"][1]["step"] > 0
    assert store.is_trained(tmp_path / "better")


def test_the_best_evaluated_policy_is_kept_across_an_interruption(tmp_path, monkeypatch):
    import pianobot.learn.train as train

    def scripted(record):
        scores = iter([0.2, 0.9, 0.4, 0.3])  # the second evaluation is the best; the last (final) is worse

        def evaluate(agent, target, env_config, episodes):
            record.append((agent.updates, agent.tensors(with_training_state=False)))
            return {"f1": next(scores), "velocity_mae": 1.0, "return": 0.0}

        return evaluate

    config = small(steps=400, eval_every=100)
    seen: list = []
    monkeypatch.setattr(train, "evaluate", scripted(seen))
    manifest = train_policy(PHRASE, config, tmp_path / "straight")
    assert (
        len(seen) == 4
        and manifest["evaluation"]["f1"] == 0.9
        and manifest["evaluation"]["step"] == manifest["evaluations"][1]["step"]
    )
    assert [e["f1"] for e in manifest["evaluations"]] == [0.2, 0.9, 0.4, 0.3]
    stored = store.load_tensors(tmp_path / "straight" / store.POLICY_FILE)
    assert all(torch.equal(stored[k], seen[1][1][k]) for k in stored)
    assert not all(torch.equal(stored[k], seen[3][1][k]) for k in stored)  # not the last policy

    # interrupted after the best evaluation, resumed: the checkpoint carried the best policy
    first: list = []
    monkeypatch.setattr(train, "evaluate", scripted(first))
    train_policy(PHRASE, config, tmp_path / "resumed", stop_after=260)
    assert len(first) == 2
    rest: list = []
    scores = iter([0.4, 0.3])
    monkeypatch.setattr(
        train, "evaluate", lambda *a: (rest.append(1), {"f1": next(scores), "velocity_mae": 1.0, "return": 0.0})[1]
    )
    resumed = train_policy(PHRASE, config, tmp_path / "resumed")
    assert len(rest) == 2 and resumed["evaluation"] == manifest["evaluation"]
    kept = store.load_tensors(tmp_path / "resumed" / store.POLICY_FILE)
    assert all(torch.equal(kept[k], stored[k]) for k in stored)


def test_training_workers_end_at_once_when_their_parent_is_terminated(tmp_path):
    """`kill PID` (SIGTERM) of `pianobot train --workers N` unwinds the command as Ctrl-C does, and its
    workers end with it at once; the pool once waited for their runs to finish (an hour's training)."""
    import os
    import signal
    import subprocess
    import sys
    import time

    script = tmp_path / "parent.py"
    script.write_text(
        "import multiprocessing, os, time\n"
        "from pianobot.cli.app import _sigterm_unwinds\n"
        "from pianobot.learn import jobs\n"
        "def nap():\n"
        "    jobs._PROGRESS.put(os.getpid())\n"
        "    time.sleep(120)\n"
        "if __name__ == '__main__':\n"
        "    context = multiprocessing.get_context('spawn')\n"
        "    queue = context.Queue()\n"
        "    with _sigterm_unwinds(), jobs.worker_pool(2, context, queue) as pool:\n"
        "        futures = [pool.submit(nap) for _ in range(2)]\n"
        "        print(queue.get(), queue.get(), flush=True)\n"
        "        time.sleep(120)\n"
    )
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        workers = [int(pid) for pid in parent.stdout.readline().split()]
        started = time.monotonic()
        os.kill(parent.pid, signal.SIGTERM)
        parent.wait(timeout=60)
    finally:  # (a parent that did not stop is not left behind by the failing test)
        parent.kill()
    assert time.monotonic() - started < 30 and "Terminated" in parent.stderr.read()
    deadline = time.monotonic() + 20
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(p) for p in workers)


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has ended
    except FileNotFoundError:
        return False


def test_training_workers_end_when_their_parent_is_killed(tmp_path):
    """`kill PID` of `pianobot train --workers N` must not leave its workers training on unseen, nor any
    other process of its (a multiprocessing manager once stayed behind, idle)."""
    import os
    import signal
    import subprocess
    import sys
    import time

    script = tmp_path / "parent.py"
    script.write_text(
        "import multiprocessing, os, time\n"
        "from concurrent.futures import ProcessPoolExecutor\n"
        "from pianobot.learn import jobs\n"
        "def nap():\n"
        "    jobs._PROGRESS.put(os.getpid())\n"
        "    time.sleep(60)\n"
        "if __name__ == '__main__':\n"
        "    context = multiprocessing.get_context('spawn')\n"
        "    queue = context.Queue()\n"
        "    with jobs.worker_pool(2, context, queue) as pool:\n"
        "        futures = [pool.submit(nap) for _ in range(2)]\n"
        "        print(queue.get(), queue.get(), flush=True)\n"
        "        time.sleep(60)\n"
    )
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    workers = [int(pid) for pid in parent.stdout.readline().split()]  # (their progress reached the parent)
    children = [int(p) for p in os.listdir("/proc") if p.isdigit() and _parent_of(int(p)) == parent.pid]
    assert set(workers) <= set(children)
    workers = children  # every process the parent started
    os.kill(parent.pid, signal.SIGKILL)
    parent.wait()

    deadline = time.monotonic() + 20
    while any(_alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(p) for p in workers)


def _parent_of(pid: int) -> int | None:
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return int(stat.read().rsplit(")", 1)[1].split()[1])
    except (FileNotFoundError, ProcessLookupError, IndexError, ValueError):
        return None


def _log_without_time(folder):
    import csv

    with open(folder / LOG_FILE, newline="") as log:
        return [{k: v for k, v in row.items() if k != "seconds"} for row in csv.DictReader(log)]


def test_training_logs_every_episode_and_draws_its_curves(tmp_path):
    config = small(steps=210, eval_every=70)
    manifest = train_policy(PHRASE, config, tmp_path / "m")
    rows = _log_without_time(tmp_path / "m")
    assert [int(r["step"]) for r in rows] == list(range(35, 211, 35))  # one row per 35-step episode
    evaluated = [r for r in rows if r["eval_f1"]]
    assert [int(r["step"]) for r in evaluated] == [e["step"] for e in manifest["evaluations"]][: len(evaluated)]
    assert all(r["critic_loss"] for r in rows if int(r["step"]) > 60) and not rows[0]["critic_loss"]  # learning from 60
    assert (tmp_path / "m" / PLOT_FILE).read_bytes()[:4] == b"\x89PNG"


class Killed(BaseException):
    """What a kill looks like to the code it interrupts: nothing runs after it."""


@pytest.mark.parametrize("point", ["tensors", "buffer", "state", "before rename", "after rename"])
def test_a_kill_at_any_point_of_a_checkpoint_write_loses_at_most_one_interval(tmp_path, monkeypatch, point):
    """The second checkpoint's write (step 140) is cut off at each of its stages; the rerun
    resumes from the first (step 70) or the second, never from step 0, ends bit-identical to an
    uninterrupted run, and leaves no temporary files."""
    from pathlib import Path

    torch.set_num_threads(1)
    config = small()
    train_policy(PHRASE, config, tmp_path / "straight")
    original, calls = store.save_checkpoint, []

    def kill(*args, **kwargs):
        raise Killed

    def rename_then_kill(self, target):
        Path.rename.__wrapped__(self, target)
        raise Killed

    rename_then_kill.__wrapped__ = Path.rename

    def breaking(folder, tensors, state, buffer):
        calls.append(state["step"])
        if len(calls) < 2:
            return original(folder, tensors, state, buffer)
        with monkeypatch.context() as m:
            if point == "tensors":
                m.setattr(store, "save_tensors", kill)
            elif point == "buffer":
                m.setattr(buffer, "save", kill)
            elif point == "state":
                m.setattr(store, "atomic_write", kill)
            elif point == "before rename":
                m.setattr(Path, "rename", kill)
            else:
                rename_then_kill.__wrapped__ = Path.rename
                m.setattr(Path, "rename", rename_then_kill)
            original(folder, tensors, state, buffer)

    monkeypatch.setattr(store, "save_checkpoint", breaking)
    with pytest.raises(Killed):
        train_policy(PHRASE, config, tmp_path / "killed")
    monkeypatch.setattr(store, "save_checkpoint", original)
    seen: list[Progress] = []
    train_policy(PHRASE, config, tmp_path / "killed", seen.append)
    resumed_at = [p.step for p in seen if p.resumed]
    assert resumed_at == ([140] if point == "after rename" else [70])
    a, b = (
        store.load_tensors(tmp_path / "straight" / store.POLICY_FILE),
        store.load_tensors(tmp_path / "killed" / store.POLICY_FILE),
    )
    assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)
    left = sorted(p.name for p in (tmp_path / "killed").iterdir())
    expected = [store.LOCK_FILE, store.MANIFEST_FILE, store.POLICY_FILE, store.CRITIC_FILE, LOG_FILE, PLOT_FILE]
    assert left == sorted(expected + ([TENSORBOARD_DIR] if (tmp_path / "killed" / TENSORBOARD_DIR).is_dir() else []))
    assert _log_without_time(tmp_path / "killed") == _log_without_time(tmp_path / "straight")  # as one run


class _Buffer:
    def save(self, path):
        path.mkdir()


def test_a_checkpoint_read_beside_a_running_training_is_one_whole_checkpoint(tmp_path, monkeypatch):
    """A report reads the checkpoint of a run that is still training: when the training replaces
    the newest checkpoint between the listing and the read (its files going one by one), the
    reader takes the new one whole (its state with its own tensors), and only a newest
    checkpoint that stays broken is reported unreadable."""
    folder = tmp_path / "m"
    store.save_checkpoint(folder, {"w": torch.zeros(1)}, {"step": 10}, _Buffer())
    stale = store._checkpoints(folder)
    store.save_checkpoint(folder, {"w": torch.ones(1)}, {"step": 20}, _Buffer())  # (removes step 10)
    (stale[0] / "buffer").mkdir(parents=True)  # step 10 half removed: its folder is still there
    listings = [stale]
    real = store._checkpoints
    monkeypatch.setattr(store, "_checkpoints", lambda f: listings.pop() if listings else real(f))
    tensors, state, buffer = store.load_checkpoint(folder)
    assert state["step"] == 20 and torch.equal(tensors["w"], torch.ones(1)) and buffer.parent.name == f"{20:010d}"
    listings.append(stale)
    assert store.checkpoint_state(folder)["step"] == 20
    (real(folder)[-1] / "state.safetensors").write_bytes(b"broken")
    with pytest.raises(PianobotError, match=r"checkpoint .*0000000020 is unreadable .*: delete it"):
        store.load_checkpoint(folder)


def test_a_due_evaluation_survives_an_interruption(tmp_path):
    """At step 70 an evaluation is due but waits for exploration to end (step 70 is not past
    it); a run interrupted there must still evaluate at the next episode end, as a straight run does."""
    config = small(steps=210, eval_every=70, checkpoint_every=70, sac=replace(small().sac, exploration_steps=70))
    straight = train_policy(PHRASE, config, tmp_path / "straight")
    assert train_policy(PHRASE, config, tmp_path / "resumed", stop_after=70) == {"interrupted_at": 70}
    resumed = train_policy(PHRASE, config, tmp_path / "resumed")
    assert [e["step"] for e in resumed["evaluations"]] == [e["step"] for e in straight["evaluations"]]
    assert straight["evaluations"][0]["step"] == 105


def test_two_runs_cannot_train_into_one_folder(tmp_path):
    import os

    with store.training_lock(tmp_path / "m"):
        with pytest.raises(PianobotError, match=f"is being trained by pianobot process {os.getpid()}"):
            train_policy(PHRASE, small(), tmp_path / "m")
    train_policy(PHRASE, small(steps=80), tmp_path / "m")  # free again once the first is done
    assert store.is_trained(tmp_path / "m")


def test_training_writes_tensorboard_events_when_it_is_installed(tmp_path):
    pytest.importorskip("tensorboard")
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    train_policy(PHRASE, small(steps=140, eval_every=70), tmp_path / "m")
    events = EventAccumulator(str(tmp_path / "m" / "tensorboard"))
    events.Reload()
    scalars = events.Tags()["scalars"]
    assert "return" in scalars and "critic_loss" in scalars and "eval/f1" in scalars
    assert [e.step for e in events.Scalars("return")] == [35, 70, 105, 140]


# -- --envs and --device (issue 20) ------------------------------------------------------------
def test_one_environment_trains_in_the_training_process_and_a_seed_repeats_it():
    """--envs 1 (the default) steps its environment in the training process: a seeded run logs an
    episode every 35 steps and evaluates at 70, 140 and the end, and the same seed gives the same
    log and evaluations to the last digit. (Figures pinned from one machine do not carry to
    another: a different CPU rounds PyBullet's floats differently and contact amplifies it, so
    this test compares a run with itself.)"""
    import csv
    import math
    import tempfile
    from pathlib import Path

    torch.set_num_threads(1)

    def run() -> tuple[list, list]:
        with tempfile.TemporaryDirectory() as scratch:
            manifest = train_policy(PHRASE, small(explore="uniform", eval_every=70), Path(scratch))
            with open(Path(scratch) / LOG_FILE, newline="") as log:
                rows = [
                    (int(r["step"]), float(r["return"]), *(r[k] for k in ("critic_loss", "actor_loss")))
                    for r in csv.DictReader(log)
                ]
        return rows, [(e["step"], e["return"], e["f1"]) for e in manifest["evaluations"]]

    rows, evaluations = run()
    assert [r[0] for r in rows] == [35, 70, 105, 140, 175] and rows[0][2:] == ("", "")
    assert all(math.isfinite(float(x)) for r in rows[1:] for x in r[2:])  # losses logged, finite
    assert [e[0] for e in evaluations] == [70, 140, 200]
    assert run() == (rows, evaluations)


def test_environments_in_worker_processes_train_checkpoint_and_resume(tmp_path):
    """--envs 2: two environments step in worker processes, one row per episode, and an
    interrupted run resumes from its checkpoint, with two environments or (the same model
    folder: --envs is not part of what is trained) with one."""
    import shutil

    config = small(envs=2, eval_every=70, env=EnvConfig(tactile=False))
    folder = store.model_dir(tmp_path, "phrase", config)
    assert folder == store.model_dir(tmp_path, "phrase", replace(config, envs=1, device="cpu"))
    assert train_policy(PHRASE, config, folder, stop_after=100) == {"interrupted_at": 140}
    assert len(store.checkpoint_state(folder)["env_rng"]) == 2  # each worker's generator
    shutil.copytree(folder, tmp_path / "other")

    seen: list[Progress] = []
    manifest = train_policy(PHRASE, config, folder, seen.append)
    assert [p.step for p in seen if p.resumed] == [140]
    assert manifest["steps"] == 200 and manifest["updates"] == 140 and manifest["config"]["envs"] == 2
    rows = _log_without_time(folder)
    assert [int(r["step"]) for r in rows] == [70, 70, 140, 140]  # both environments' episodes end together
    assert [bool(r["eval_f1"]) for r in rows] == [True, False, True, False]  # an evaluation is logged once
    assert [e["step"] for e in manifest["evaluations"]] == [70, 140, 200]

    other = train_policy(PHRASE, replace(config, envs=1), tmp_path / "other")  # resumed with one environment
    assert other["steps"] == 200 and other["updates"] == 140 and store.is_trained(tmp_path / "other")


def test_the_learner_runs_on_the_cpu_here_and_a_missing_gpu_is_one_line(tmp_path, monkeypatch):
    from pianobot.agent.sac import resolve_device

    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    assert resolve_device("auto") == resolve_device("cpu") == torch.device("cpu")
    with pytest.raises(PianobotError, match="train.device cuda: torch .* sees no CUDA GPU") as error:
        resolve_device("cuda")
    assert "\n" not in str(error.value)
    with pytest.raises(PianobotError, match="train.device cuda"):
        train_policy(PHRASE, small(device="cuda"), tmp_path / "m")
    with pytest.raises(ValueError, match="device must be one of auto, cpu, cuda"):
        small(device="gpu")
    manifest = train_policy(PHRASE, small(steps=80, env=EnvConfig(tactile=False)), tmp_path / "m")
    assert manifest["device"] == "cpu" and manifest["config"]["device"] == "auto"


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA GPU")
def test_a_run_on_the_gpu_checkpoints_and_stores_tensors_that_load_on_the_cpu(tmp_path):
    config = small(device="cuda")
    train_policy(PHRASE, config, tmp_path / "m", stop_after=100)
    tensors, _, _ = store.load_checkpoint(tmp_path / "m")
    assert all(t.device.type == "cpu" for t in tensors.values())
    manifest = train_policy(PHRASE, replace(config, device="cpu"), tmp_path / "m")  # resumed on the CPU
    assert manifest["device"] == "cpu"
    env = make_env(PHRASE, config.env)
    assert load_policy(tmp_path / "m", env).act(env.reset(seed=0)[0]).shape == (13,)
