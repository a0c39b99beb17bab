"""Training: one SAC policy per phrase (or per task family), with evaluation, checkpoints and resume.

:func:`train_policy` is the loop, to be read top to bottom: explore, then act with the policy
and learn from the replay buffer at ``update_ratio`` gradient steps per environment step;
evaluate every ``eval_every`` steps; at the first episode end after every
``checkpoint_every`` steps, write a checkpoint that holds everything (networks, optimisers,
buffer, random generators), so that running the same command again continues exactly where an
interrupted run stopped. The policy stored at the end is the best one evaluated (SAC's
evaluations swing by tenths of F1 from one to the next; the last is not always the best).
:func:`train_piece` does the plumbing for a whole piece: phrases,
skipping what is already trained, parallel workers.
"""

from __future__ import annotations

import os
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Callable

import numpy as np
import torch

from pianobot.agent import store
from pianobot.agent.buffer import ReplayBuffer
from pianobot.agent.sac import SAC, SACConfig, score_size, vector_size
from pianobot.env.piano import JOINT_KINDS, EnvConfig, PianoEnv
from pianobot.errors import PianobotError
from pianobot.learn.explore import Explorer
from pianobot.music.metrics import compare
from pianobot.music.phrases import Phrase
from pianobot.music.piece import Piece
from pianobot.sim.recorder import NoteRecorder

EVAL_SEED = 10_000
"""Evaluation episodes use seeds EVAL_SEED, EVAL_SEED + 1, ...: the same hand starts for every evaluation."""


TASK_EVAL_EPISODES = 20
"""Evaluation episodes when training on a task family: every instance differs, and 3 or 5 of
them stopped runs on a lucky evaluation (5 instances at F1 0.90 played 30 others at 0.58)."""

TRAIN_JOINTS = JOINT_KINDS
"""The finger joints a policy moves by default: all four (abduction is needed for chords and
for keys beside the wrist's line; freezing joints, as the paper did, is the --joints option)."""


@dataclass(frozen=True)
class TrainConfig:
    """One training run of one policy. Its hash (with the phrase's) names the model folder."""

    steps: int = 50_000
    """Environment steps, exploration included."""
    seed: int = 0
    explore: str = "scripted"
    """'uniform', 'repeat', 'prior' (the paper's best) or 'scripted' (ours)."""
    eval_every: int = 5_000
    eval_episodes: int = 3
    checkpoint_every: int = 5_000
    until_f1: float | None = None
    """Stop early once an evaluation reaches this note F1 (None: always train ``steps`` steps)."""
    sac: SACConfig = field(default_factory=SACConfig)
    env: EnvConfig = field(default_factory=lambda: EnvConfig(actuated=TRAIN_JOINTS))


@dataclass
class Progress:
    """What the loop reports to whoever displays it."""

    step: int
    steps: int
    episode_return: float | None = None
    eval_f1: float | None = None
    losses: dict | None = None


def agent_env_config(config: TrainConfig) -> EnvConfig:
    """The environment as the agent sees it: tactile images at the agent's resolution."""
    return replace(config.env, tactile_pool=config.sac.tactile_resolution)


def make_agent(env: PianoEnv, config: TrainConfig) -> SAC:
    space = env.observation_space
    tactile = space["tactile"].shape if "tactile" in space.spaces else None
    score = config.sac.score_input
    return SAC(vector_size(space, score), score_size(space, score), tactile, env.action_space.shape[0], config.sac)


def make_env(target: Piece | str, env_config: EnvConfig) -> PianoEnv:
    return PianoEnv(task=target, config=env_config) if isinstance(target, str) else PianoEnv(piece=target, config=env_config)


def evaluate(agent: SAC, target: Piece | str, env_config: EnvConfig, episodes: int, first_seed: int = EVAL_SEED) -> dict:
    """Deterministic policy on fixed hand starts (and task instances), seeds ``first_seed``,
    ``first_seed + 1``, ...: mean note F1, velocity error and return."""
    env = make_env(target, env_config)
    f1s, errors, returns = [], [], []
    for i in range(episodes):
        observation, info = env.reset(seed=first_seed + i)
        recorder, total = NoteRecorder(), 0.0
        while True:
            observation, reward, terminated, truncated, step_info = env.step(agent.act(*agent.split(observation), deterministic=True))
            recorder.add(step_info["events"], step_info["fingers"])
            total += reward
            if terminated or truncated:
                break
        report = compare(info["piece"], recorder.piece(end=env.world.time, start=env.score_start))
        f1s.append(report.f1)
        returns.append(total)
        if report.velocity_mae is not None:
            errors.append(report.velocity_mae)
    env.close()
    return {
        "f1": float(np.mean(f1s)),
        "velocity_mae": float(np.mean(errors)) if errors else None,
        "return": float(np.mean(returns)),
    }


BEST_PREFIX = "best."
"""Checkpoint tensors of the best policy evaluated so far are stored under this prefix."""


def best_policy_tensors(checkpoint_tensors: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
    """The best evaluated policy's tensors in a checkpoint, under their own names."""
    return {k[len(BEST_PREFIX) :]: v for k, v in checkpoint_tensors.items() if k.startswith(BEST_PREFIX)}


def better(figures: dict, than: dict | None) -> bool:
    """Whether an evaluation beats another: higher note F1 first, then higher return."""
    if than is None:
        return True
    return (figures["f1"], figures["return"]) > (than["f1"], than["return"])


def train_policy(
    target: Piece | str,
    config: TrainConfig,
    folder: Path,
    report: Callable[[Progress], None] = lambda p: None,
    stop_after: int | None = None,
    about: dict | None = None,
) -> dict:
    """Train one policy for a phrase (a Piece) or a task family (its name); store it in ``folder``.

    ``stop_after`` ends the run after that many steps as an interruption would (tests);
    ``about`` goes into the manifest (piece, phrase hash, ...).
    """
    torch.manual_seed(config.seed)  # before the networks are made: their first weights come from it
    env_config = agent_env_config(config)
    env = make_env(target, env_config)
    agent = make_agent(env, config)
    space = env.observation_space
    tactile_shape = space["tactile"].shape if "tactile" in space.spaces else None
    buffer = ReplayBuffer(min(config.sac.buffer_size, config.steps), vector_size(space, config.sac.score_input), tactile_shape, env.action_space.shape[0])
    rng = np.random.default_rng(config.seed)
    explorer = Explorer(config.explore, env.action_space.shape[0], env_config, rng, select=env.actuated)
    step, episode, update_debt, evaluations = 0, 0, 0.0, []
    best, best_tensors = None, None  # the best evaluation so far and its policy's tensors
    seconds_before = 0.0  # wall-clock time spent before an interruption

    checkpoint = store.load_checkpoint(folder)
    if checkpoint is not None:  # continue an interrupted run exactly
        tensors, state, buffer_folder = checkpoint
        agent.load_tensors({k: v for k, v in tensors.items() if not k.startswith(BEST_PREFIX)})
        if state.get("best") is not None:
            best = state["best"]
            best_tensors = best_policy_tensors(tensors)
        torch.set_rng_state(tensors["torch_rng"])
        buffer.load(buffer_folder, state["buffer_size"], state["buffer_cursor"])
        rng.bit_generator.state = state["rng"]
        step, episode, update_debt, evaluations = state["step"], state["episode"], state["update_debt"], state["evaluations"]
        agent.updates = state["updates"]
        seconds_before = state.get("seconds", 0.0)
        env.reset(seed=config.seed)  # creates the env's generator, then restore its state
        env.np_random.bit_generator.state = state["env_rng"]
        observation, _ = env.reset()
    else:
        observation, _ = env.reset(seed=config.seed)
    explorer.reset()
    next_eval = (step // config.eval_every + 1) * config.eval_every
    next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
    episode_return, losses, final = 0.0, None, None
    started = time.perf_counter()

    while step < config.steps:
        vector, tactile = agent.split(observation)
        taught = explorer.teach(observation)  # the scripted pianist's action here, or None
        if step < config.sac.exploration_steps:
            action = explorer.act(observation, taught)
        else:
            action = agent.act(vector, tactile)
        observation, reward, terminated, truncated, _ = env.step(action)
        next_vector, next_tactile = agent.split(observation)
        buffer.add(vector, tactile, action, reward, terminated, next_vector, next_tactile, expert=taught)
        episode_return += reward
        step += 1

        if step > config.sac.exploration_steps:  # learn
            update_debt += config.sac.update_ratio
            while update_debt >= 1.0:
                losses = agent.update(buffer.sample(config.sac.batch_size, rng))
                update_debt -= 1.0

        if terminated or truncated:
            episode += 1
            report(Progress(step, config.steps, episode_return=episode_return, losses=losses))
            episode_return = 0.0
            if step >= next_eval and step > config.sac.exploration_steps:
                figures = evaluate(agent, target, env_config, config.eval_episodes)
                temperature = {k: round(losses[k], 4) for k in ("alpha", "entropy")} if losses else {}
                evaluations.append({"step": step, **figures, **temperature})
                if better(figures, best):
                    best, best_tensors = {"step": step, **figures}, agent.tensors(with_training_state=False)
                report(Progress(step, config.steps, eval_f1=figures["f1"]))
                next_eval = (step // config.eval_every + 1) * config.eval_every
                if config.until_f1 is not None and figures["f1"] >= config.until_f1:
                    final = {"step": step, **figures}  # good enough: stop here
                    break
            if step >= next_checkpoint and step < config.steps:
                state = {
                    "step": step, "episode": episode, "update_debt": update_debt, "updates": agent.updates,
                    "evaluations": evaluations, "rng": rng.bit_generator.state, "env_rng": env.np_random.bit_generator.state,
                    "buffer_size": buffer.size, "buffer_cursor": buffer.cursor, "best": best,
                    "seconds": seconds_before + time.perf_counter() - started,
                }
                kept = {BEST_PREFIX + k: v for k, v in (best_tensors or {}).items()}
                store.save_checkpoint(folder, {**agent.tensors(), "torch_rng": torch.get_rng_state(), **kept}, state, buffer)
                next_checkpoint = (step // config.checkpoint_every + 1) * config.checkpoint_every
            if stop_after is not None and step >= stop_after:
                env.close()
                return {"interrupted_at": step}
            observation, _ = env.reset()
            explorer.reset()
        elif step % 200 == 0:
            report(Progress(step, config.steps))
    env.close()

    tensors = agent.tensors(with_training_state=False)
    if final is None:
        final = {"step": step, **evaluate(agent, target, env_config, config.eval_episodes)}
        evaluations.append(final)
        if best is not None and better(best, final):  # an earlier policy played better: keep that one
            final, tensors = best, best_tensors
    manifest = {
        **(about or {}),
        "target": target if isinstance(target, str) else [asdict(n) for n in target.notes],
        "steps": step,
        "updates": agent.updates,
        "seconds": round(seconds_before + time.perf_counter() - started, 1),  # across interruptions
        "evaluation": final,
        "evaluations": evaluations,
        "config": asdict(config),
    }
    store.save_policy(folder, tensors, manifest)
    store.drop_checkpoint(folder)
    return manifest


# -- a whole piece -----------------------------------------------------------------------------
def phrase_target(phrase: Phrase) -> Piece:
    """A phrase as the piece its policy learns: its first note at time 0."""
    return phrase.piece(lead_in=0.0)


def load_policy(folder: Path, config: TrainConfig, env: PianoEnv) -> SAC:
    agent = make_agent(env, config)
    tensors = store.load_tensors(folder / store.POLICY_FILE)
    try:
        agent.load_tensors(tensors, with_training_state=False)
    except (RuntimeError, KeyError) as e:
        raise PianobotError(f"{folder / store.POLICY_FILE} does not fit this configuration ({str(e).splitlines()[0]}): retrain with --force") from None
    return agent


def config_from_manifest(manifest: dict) -> TrainConfig:
    """Rebuild the TrainConfig a stored policy was trained with."""
    from pianobot.music.instrument import HandSpec, KeyboardSpec
    from pianobot.env.rewards import RewardConfig
    from pianobot.sim.hand import FingerGeometry, HandConfig
    from pianobot.sim.keyboard import KeyboardConfig, KeyGeometry, VelocityCurve
    from pianobot.sim.tactile import TactileConfig
    from pianobot.sim.world import WorldConfig

    try:
        c = manifest["config"]
        e, w = c["env"], c["env"]["world"]
        kb, hd = w["keyboard"], w["hand"]
        keyboard = KeyboardConfig(
            spec=KeyboardSpec(**kb["spec"]), geometry=KeyGeometry(**kb["geometry"]), curve=VelocityCurve(**kb["curve"]),
            **{k: v for k, v in kb.items() if k not in ("spec", "geometry", "curve")},
        )
        geometry = FingerGeometry(**{**hd["geometry"], "flexion_limits": tuple(map(tuple, hd["geometry"]["flexion_limits"]))})
        hand = HandConfig(spec=HandSpec(tuple(hd["spec"]["fingers"])), geometry=geometry,
                          **{k: v for k, v in hd.items() if k not in ("spec", "geometry")})
        world = WorldConfig(keyboard=keyboard, hand=hand, **{k: v for k, v in w.items() if k not in ("keyboard", "hand")})
        pool = tuple(e["tactile_pool"]) if e["tactile_pool"] is not None else None
        env = EnvConfig(world=world, reward=RewardConfig(**e["reward"]), tactile_sensor=TactileConfig(**e["tactile_sensor"]),
                        tactile_pool=pool, actuated=tuple(e["actuated"]),
                        # manifests from before these existed: without
                        target_velocity=e.get("target_velocity", False), target_onsets=e.get("target_onsets", False),
                        **{k: v for k, v in e.items() if k not in ("world", "reward", "tactile_sensor", "tactile_pool", "actuated",
                                                                   "target_velocity", "target_onsets")})
        s = c["sac"]
        sac = SACConfig(**{**s, "tactile_resolution": tuple(s["tactile_resolution"]) if s["tactile_resolution"] else None,
                           "log_std_bounds": tuple(s["log_std_bounds"]),
                           "score_input": s.get("score_input", True)})  # manifests from before it existed read the score
        return TrainConfig(sac=sac, env=env, **{k: v for k, v in c.items() if k not in ("sac", "env")})
    except (KeyError, TypeError, ValueError) as e:
        raise PianobotError(f"model manifest does not describe a pianobot configuration ({e!r}): retrain with --force") from None


@dataclass
class PhraseJob:
    """One policy to train: a phrase (by content hash) or a task family, and the phrases that use it."""

    key: str
    target: Piece | str
    folder: Path
    phrases: list[int]
    piece: str = ""

    def about(self) -> dict:
        return {"key": self.key, "piece": self.piece, "phrases": self.phrases}


def _exit_with_parent(parent: int, every: float = 0.5) -> None:
    """Worker initializer: end this process when the process that started it is gone.

    Ctrl-C reaches every process in the terminal's group, but a parent killed on its own
    (``kill PID``, a closed session) would leave its workers training on unseen. Checkpoints
    are written atomically, so ending a worker at any moment loses at most the steps since its
    last checkpoint, which the same command trains again."""

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(every)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="exit-with-parent").start()


def _run_job(job: PhraseJob, config: TrainConfig, queue=None, threads: int | None = None) -> dict:
    if threads is not None:
        torch.set_num_threads(threads)

    def report(progress: Progress) -> None:
        if queue is not None:
            queue.put((job.key, progress))

    return train_policy(job.target, config, job.folder, report, about=job.about())


def plan_jobs(phrases: list[Phrase], config: TrainConfig, root: Path, force: bool, piece: str = "") -> tuple[list[PhraseJob], list[PhraseJob]]:
    """(jobs to train, jobs already trained): identical phrases share one job."""
    by_hash: dict[str, PhraseJob] = {}
    for phrase in phrases:
        if phrase.hash in by_hash:
            by_hash[phrase.hash].phrases.append(phrase.index)
        else:
            folder = store.model_dir(root, phrase.hash, config)
            by_hash[phrase.hash] = PhraseJob(phrase.hash, phrase_target(phrase), folder, [phrase.index], piece)
    todo, done = [], []
    for job in by_hash.values():
        if store.is_trained(job.folder) and not force:
            done.append(job)
        else:
            if force and job.folder.exists():
                for name in (store.POLICY_FILE, store.MANIFEST_FILE):
                    (job.folder / name).unlink(missing_ok=True)
            todo.append(job)
    return todo, done


def run_jobs(
    jobs: list[PhraseJob], config: TrainConfig, workers: int, on_progress: Callable[[str, Progress], None], threads: int = 1
) -> dict[str, dict]:
    """Train every job, ``workers`` at a time in separate processes (1: in this process), each with
    ``threads`` torch threads (more threads than cores makes torch's thread pools spin against each other)."""
    results: dict[str, dict] = {}
    if workers <= 1 or len(jobs) <= 1:
        torch.set_num_threads(threads)
        for job in jobs:
            results[job.key] = train_policy(job.target, config, job.folder, lambda p, key=job.key: on_progress(key, p), about=job.about())
        return results
    import multiprocessing

    manager = multiprocessing.Manager()
    queue = manager.Queue()
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_exit_with_parent, initargs=(os.getpid(),)) as pool:
        futures = {pool.submit(_run_job, job, config, queue, threads): job for job in jobs}
        pending = set(futures)
        while pending:
            while not queue.empty():
                key, progress = queue.get()
                on_progress(key, progress)
            finished = {f for f in pending if f.done()}
            for future in finished:
                results[futures[future].key] = future.result()
            pending -= finished
            time.sleep(0.2)
        while not queue.empty():
            key, progress = queue.get()
            on_progress(key, progress)
    return results
