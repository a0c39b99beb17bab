"""The sustain pedal (issue 59): read from a file's control change 64, worked by the foot in the
simulation as written (or as an action), recorded, written back as CC64, heard in the sound and
scored; the keys play exactly as without it."""

import mido
import numpy as np
import pytest
from conftest import midi_file, off, on, run

from pianobot.agent.store import config_hash
from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.env.rewards import RewardConfig
from pianobot.errors import PianobotError
from pianobot.learn.config import TrainConfig
from pianobot.music.metrics import compare, pedal_f1
from pianobot.music.midi_io import read_midi, read_pedal
from pianobot.music.midi_out import midi_bytes
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Note, Piece
from pianobot.perform.audio import synthesize
from pianobot.perform.perform import PLAY_CONFIG, perform
from pianobot.perform.rollout import rollout
from pianobot.pianist.scripted import ScriptedPianist

STEP = 1 / 20  # the control step (s)


def cc(value: int) -> mido.Message:
    return mido.Message("control_change", control=64, value=value)


def test_pedal_spans_are_validated_and_merged():
    with pytest.raises(PianobotError, match="overlap"):
        Pedal(((0.0, 1.0), (0.5, 2.0)))
    with pytest.raises(PianobotError, match="come up after"):
        Pedal(((1.0, 1.0),))
    pedal = Pedal.from_changes([(0.5, True), (0.7, True), (1.0, False), (1.0, True), (2.0, False), (3.0, True)], end=4)
    assert pedal.spans == ((0.5, 1.0), (1.0, 2.0), (3.0, 4.0))  # a press while down changes nothing
    assert Pedal.from_changes([(3.0, True)]).spans == ()  # never released, no end: nothing held
    assert pedal.down_at(0.5) and pedal.down_at(1.99) and not pedal.down_at(2.0) and not pedal.down_at(0.49)
    # a change (up and down at once) lifts the foot for the step it falls in
    assert list(pedal.steps(10, 2.0)) == [False, True, False, True, False, False, True, True, False, False]
    assert list(Pedal(((0.0, 0.9), (1.3, 2.0))).steps(4, 2.0)) == [True, True, False, True]  # up at a step
    assert list(Pedal(((0.0, 1.1), (1.3, 2.0))).steps(4, 2.0)) == [True, True, True, False]  # up between steps
    assert pedal.shift(-1.0).spans == ((0.0, 1.0), (2.0, 3.0))  # cut at 0
    assert pedal.until(3.5).spans == ((0.5, 1.0), (1.0, 2.0), (3.0, 3.5))


def test_sounding_holds_a_released_note_until_the_pedal_rises_or_its_key_is_struck_again():
    pedal = Pedal(((1.0, 3.0),))
    piece = Piece.of(
        [Note(0.0, 60, 0.5), Note(1.2, 64, 1.5), Note(1.5, 67, 1.8), Note(2.0, 67, 2.2), Note(2.5, 72, 3.5)]
    )
    sounding = {(n.pitch, n.onset): n.offset for n in pedal.sounding(piece).notes}
    assert sounding[(60, 0.0)] == 0.5  # let go before the pedal went down
    assert sounding[(64, 1.2)] == 3.0  # rings until the pedal rises
    assert sounding[(67, 1.5)] == 2.0  # until its own key is struck again
    assert sounding[(67, 2.0)] == 3.0
    assert sounding[(72, 2.5)] == 3.5  # still held when the pedal rose
    assert Pedal().sounding(piece) == piece


def test_cc64_is_read_on_the_tempo_map_with_half_pedal_rounded_at_64(tmp_path):
    # 480 ticks a beat; 120 bpm for the first beat, then 60 bpm
    events = [(0, on(60)), (960, off(60)), (240, cc(64)), (480, cc(63)), (720, cc(127)), (1200, cc(0))]
    path = midi_file(tmp_path / "p.mid", [("Piano", events)], tempo_events=((0, 500_000), (480, 1_000_000)))
    assert read_pedal(path).spans == ((0.25, 0.5), (1.0, 2.0))
    assert read_pedal(path, bpm=60).spans == ((0.5, 1.0), (1.5, 2.5))  # load.tempo re-times it as the notes


def test_the_pedal_goes_out_as_cc64_and_comes_back_the_same(tmp_path):
    piece = Piece.of([Note(0.0, 60, 0.4), Note(0.5, 62, 0.9, hand="right"), Note(0.5, 48, 1.5, hand="left")])
    pedal = Pedal(((0.1, 0.45), (0.45, 1.2)))  # a release and a press at one tick: the release first
    data = midi_bytes(piece, pedal=pedal)
    path = tmp_path / "out.mid"
    path.write_bytes(data)
    values = [m.value for t in mido.MidiFile(path).tracks for m in t if m.type == "control_change"]
    assert values == [127, 0, 127, 0]
    assert read_pedal(path) == pedal
    assert read_midi(path) == piece


def test_pedal_f1_matches_presses_and_releases_within_the_tolerance():
    pedal = Pedal(((1.0, 2.0), (3.0, 4.0)))
    assert pedal_f1(pedal, pedal) == (1.0, 0.0)
    f1, error = pedal_f1(pedal, pedal.shift(0.03))
    assert f1 == 1.0 and error == pytest.approx(0.03)
    assert pedal_f1(pedal, pedal.shift(0.2))[0] == 0.0
    assert pedal_f1(pedal, Pedal(((1.0, 2.0),)))[0] == pytest.approx(2 * 2 / 6)
    piece = Piece.of([Note(0.0, 60, 0.5), Note(1.2, 64, 1.5)])
    plain = compare(piece, piece)
    assert plain.pedal_f1 is None and plain.sounding_f1_with_offsets is None
    # the keys let go early, the pedal held them: F1 with offsets on sounding durations forgives it
    played = Piece.of([Note(0.0, 60, 0.5), Note(1.2, 64, 1.25)])
    with_pedal = compare(Piece.of([Note(0.0, 60, 0.5), Note(1.2, 64, 2.0)]), played, pedals=(pedal, pedal))
    assert with_pedal.f1_with_offsets == 0.5 and with_pedal.sounding_f1_with_offsets == 1.0


PHRASE = Piece.of([Note(0.5, 60, 0.9, 80, 2), Note(1.0, 64, 1.4, 80, 3), Note(1.5, 67, 2.2, 80, 4)])
WRITTEN = Pedal(((0.4, 1.0), (1.1, 2.0)))


def test_the_foot_follows_the_written_pedal_and_the_keys_play_as_without_it():
    with_pedal = perform(PHRASE, "scripted", PLAY_CONFIG, seed=1, pedal=WRITTEN)
    without = perform(PHRASE, "scripted", PLAY_CONFIG, seed=1)
    assert with_pedal.played == without.played  # the pedal is sound, not physics
    assert without.pedal == Pedal()
    assert len(with_pedal.pedal) == len(WRITTEN)
    for (down, up), (played_down, played_up) in zip(WRITTEN.spans, with_pedal.pedal.spans):
        assert abs(played_down - down) <= STEP / 2 + 1e-9 and abs(played_up - up) <= STEP / 2 + 1e-9
    assert with_pedal.report().pedal_f1 == 1.0


def test_the_pedal_as_an_action_is_observed_rewarded_and_used_by_the_scripted_pianist():
    config = EnvConfig(tactile=False, pedal_action=True)
    env = PianoEnv(piece=PHRASE, config=config, pedal=WRITTEN)
    plain = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False))
    assert env.action_space.shape[0] == plain.action_space.shape[0] + 1
    observation, _ = env.reset(seed=0)
    assert observation["pedal"].shape == (config.lookahead + 1,)
    action = np.zeros(env.action_space.shape, np.float32)
    action[-1] = 1.0  # down, while the score's pedal is up (the lead-in)
    _, _, _, _, info = env.step(action)
    assert info["pedal"] is True and info["reward_terms"]["pedal"] == 0.0
    action[-1] = -1.0
    _, _, _, _, info = env.step(action)
    assert info["pedal"] is False and info["reward_terms"]["pedal"] == pytest.approx(RewardConfig().pedal_weight)
    played = rollout(env, ScriptedPianist(config), seed=1)
    env.close()
    plain.close()
    assert pedal_f1(WRITTEN, played.pedal)[0] == 1.0
    assert played.report().f1 == 1.0


def test_a_run_without_the_pedal_as_an_action_keeps_its_folder_name():
    base = TrainConfig()
    other_weight = TrainConfig(env=EnvConfig(reward=RewardConfig(pedal_weight=1.0)))
    footed = TrainConfig(env=EnvConfig(pedal_action=True))
    assert config_hash(base) == config_hash(other_weight) == "a65459f65767"
    assert config_hash(footed) != config_hash(base)


def test_the_sound_rings_while_the_pedal_holds_it():
    piece = Piece.of([Note(0.0, 69, 0.2)])
    dry, _ = synthesize(piece, sample_rate=8000)
    wet, _ = synthesize(piece, sample_rate=8000, pedal=Pedal(((0.1, 1.0),)))
    late = slice(int(0.5 * 8000), int(0.9 * 8000))  # after the key rose, before the pedal did
    energy = lambda audio: float(np.abs(audio[late]).sum()) if len(audio) > late.stop else 0.0  # noqa: E731
    assert energy(wet) > 10 * max(energy(dry), 1e-9)


def test_play_writes_the_files_pedal_and_score_reports_it(tmp_path):
    """A one-hand recording with pedal: out.mid's CC64 at the file's pedal times, within a control
    step; --no-pedal plays none; score shows the pedal's figures."""
    notes = [(0, on(60)), (400, off(60)), (480, on(64)), (880, off(64)), (960, on(67)), (1400, off(67))]
    pedal = [(100, cc(100)), (470, cc(0)), (500, cc(80)), (1500, cc(0))]  # 120 bpm: 480 ticks = 0.5 s
    song = midi_file(tmp_path / "song.mid", [("Piano", notes + pedal)])
    out = tmp_path / "out.mid"
    result = run("play", song, "-o", out, "--controller", "scripted", "--quiet")
    assert result.exit_code == 0, result.output
    written, played = read_pedal(song), read_pedal(out)
    assert len(played) == len(written) == 2
    for a, b in zip(written.changes(), played.changes()):
        assert a[1] == b[1] and abs(a[0] - b[0]) <= STEP
    scored = run("score", out, song, "--all")
    assert scored.exit_code == 0 and "sustain pedal" in scored.output and "F1 1.000" in scored.output
    unpedalled = run("score", out, song, "--all", "--no-pedal")
    assert unpedalled.exit_code == 0 and "sustain pedal" not in unpedalled.output
    dry = tmp_path / "dry.mid"
    assert run("play", song, "-o", dry, "--controller", "scripted", "--quiet", "--no-pedal").exit_code == 0
    assert read_pedal(dry) == Pedal()
    assert read_midi(dry) == read_midi(out)


def test_two_hands_have_one_foot_beside_them():
    from pianobot.env.two_hands import HandsEnv
    from pianobot.music.instrument import KeyboardSpec
    from pianobot.music.window import Window

    keys, config = KeyboardSpec(), EnvConfig(tactile=False)
    parts = {"right": (Window("right", keys, -1), PHRASE), "left": (Window("left", keys, -1), PHRASE)}
    with pytest.raises(ValueError, match="one foot"):
        HandsEnv(parts, {"right": EnvConfig(tactile=False, pedal_action=True), "left": config})
    env = HandsEnv(parts, {"right": config, "left": config}, pedal=WRITTEN, pedal_action=True)
    assert env.action_space["pedal"].shape == (1,) and "pedal" in env.observation_space.spaces
    observations, _ = env.reset(seed=0)
    assert observations["pedal"].shape == (config.lookahead + 1,)
    idle = {h: np.zeros(env.action_space[h].shape, np.float32) for h in ("right", "left")}
    _, _, _, _, info = env.step({**idle, "pedal": np.ones(1, np.float32)})
    assert info["pedal"] is True and all(i["pedal"] is True for i in info["hands"].values())
    env.close()
    written = HandsEnv(parts, {"right": config, "left": config}, pedal=WRITTEN)  # the foot as written
    written.reset(seed=0)
    downs = [written.step(idle)[4]["pedal"] for _ in range(written.horizon)]
    written.close()
    lead = written.hands["right"].lead_steps
    assert downs == [False] * lead + WRITTEN.steps(written.horizon - lead, 20.0).tolist()


def test_a_policy_of_the_default_actor_reads_the_score_s_pedal_and_moves_the_foot():
    from pianobot.agent.config import SACConfig
    from pianobot.agent.policy import make_agent
    from pianobot.agent.sac import split_observation

    env = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False, pedal_action=True), pedal=WRITTEN)
    observation, _ = env.reset(seed=0)
    agent = make_agent(env, SACConfig(hidden=16, batch_size=4))
    plain = PianoEnv(piece=PHRASE, config=EnvConfig(tactile=False))
    assert len(split_observation(observation)[0]) == len(split_observation(plain.reset(seed=0)[0])[0]) + 11
    assert agent.act(observation).shape == env.action_space.shape
    with pytest.raises(ValueError, match="no foot"):
        make_agent(env, SACConfig(hidden=16, actor="fingers"))
    env.close()
    plain.close()


def test_a_pedal_long_after_the_last_note_is_not_read(tmp_path):
    """What the pedal holds has died away RING seconds after the last note: a stray press an hour on
    neither refuses the file nor lengthens the simulation."""
    from pianobot.music.pedal import RING

    hour = 480 * 2 * 3600  # ticks at 120 bpm
    events = [(0, on(60)), (480, off(60)), (240, cc(127)), (hour, cc(127)), (hour + 480, cc(0))]
    path = midi_file(tmp_path / "stray.mid", [("Piano", events)])
    assert read_pedal(path).spans == ((0.25, 0.5 + RING),)  # (down from 0.25 s, never up before the stray one)
