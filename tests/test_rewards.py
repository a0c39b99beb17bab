import numpy as np
import pytest

from pianobot.env.rewards import (
    RewardConfig,
    gate,
    linear_distance,
    reward_terms,
    squared_distance,
    wasserstein_distance,
)

L = 6


def vec(**keys):
    out = np.zeros(L)
    for k, v in keys.items():
        out[int(k[1:])] = v
    return out


def test_linear_and_squared_distances():
    played, target = vec(k1=0.5, k3=0.2), vec(k1=0.7, k2=0.4)
    assert linear_distance(played, target) == pytest.approx(0.2 + 0.4 + 0.2)
    assert squared_distance(played, target) == pytest.approx(0.04 + 0.16 + 0.04)


def test_wasserstein_is_zero_only_when_played_equals_target():
    target = vec(k1=0.5, k4=0.8)
    assert wasserstein_distance(target, target, 0.5, 0.1) == 0
    assert wasserstein_distance(vec(k1=0.5, k4=0.7), target, 0.5, 0.1) == pytest.approx(0.1)


def test_wasserstein_adds_removes_and_moves_at_the_cheapest_cost():
    sigma, key_cost = 0.5, 0.1
    target = vec(k2=0.6)
    assert wasserstein_distance(vec(), target, sigma, key_cost) == pytest.approx(sigma)  # add one key
    assert wasserstein_distance(vec(k5=0.3), vec(), sigma, key_cost) == pytest.approx(sigma)  # remove one
    # a neighbouring key with the right velocity: moving (0.1) beats removing and adding (1.0)
    assert wasserstein_distance(vec(k3=0.6), target, sigma, key_cost) == pytest.approx(0.1)
    # a far key: moving 5 keys... still cheaper than 2 sigma? 0.5 < 1.0, yes
    assert wasserstein_distance(vec(k0=0.6, k5=0.6), vec(k0=0.6), sigma, key_cost) == pytest.approx(sigma)
    # brute force over the definition for a small case: min over X of sum d(X_i, T_i) + sigma |X sym-diff S|
    played, target = vec(k0=0.2, k4=0.9), vec(k1=0.3, k3=0.9, k5=0.1)
    best = brute_force(played, target, sigma, key_cost)
    assert wasserstein_distance(played, target, sigma, key_cost) == pytest.approx(best)


def brute_force(played, target, sigma, key_cost):
    import itertools

    s = [(k, played[k]) for k in np.flatnonzero(played)]
    t = [(k, target[k]) for k in np.flatnonzero(target)]
    best = np.inf
    # each target is either matched to a distinct played key or added; unmatched played keys are removed
    for choice in itertools.product(range(-1, len(s)), repeat=len(t)):
        used = [c for c in choice if c >= 0]
        if len(used) != len(set(used)):
            continue
        cost = 0.0
        for (tk, tv), c in zip(t, choice):
            cost += sigma if c < 0 else key_cost * abs(s[c][0] - tk) + abs(s[c][1] - tv)
        cost += sigma * (len(s) - len(used))
        best = min(best, cost)
    return best


def test_fingering_gate_withholds_credit_from_the_wrong_finger():
    played, target = vec(k1=0.5, k2=0.5), vec(k1=0.5, k2=0.5)
    played_finger = np.array([0, 3, 2, 0, 0, 0])
    target_finger = np.array([0, 3, 3, 0, 0, 0])
    gated = gate(played, played_finger, target, target_finger)
    assert gated.tolist() == vec(k1=0.5).tolist()  # key 2 pressed by finger 2 instead of 3: no credit
    # an extra key (not in the target) stays penalised whoever pressed it
    assert gate(vec(k4=0.5), np.array([0, 0, 0, 0, 2, 0]), vec(), np.zeros(L, int))[4] == 0.5


@pytest.mark.parametrize("kind", ["linear", "squared", "wasserstein"])
def test_terms_sum_to_the_reward_and_a_perfect_step_scores_the_constant(kind):
    config = RewardConfig(kind=kind)
    target = vec(k2=0.7)
    fingers = np.array([0, 0, 3, 0, 0, 0])
    perfect = reward_terms(config, target, fingers, target, fingers)
    assert sum(perfect.values()) == pytest.approx(config.constant)
    wrong = reward_terms(config, vec(k3=0.7), fingers, target, fingers)
    assert set(wrong) == {"constant", kind} and sum(wrong.values()) < config.constant


def test_unknown_reward_is_refused():
    with pytest.raises(ValueError, match="linear, squared, wasserstein"):
        RewardConfig(kind="cubic")


def test_closeness_bonus_rewards_fingertips_near_their_keys():
    from pianobot.env.rewards import closeness

    assert closeness(np.array([0.0, 0.0]), 0.02) == 1.0
    assert closeness(np.array([0.02]), 0.02) == pytest.approx(np.exp(-1))
    assert closeness(np.array([0.2]), 0.02) < 1e-10
    assert closeness(np.zeros(0), 0.02) == 0.0
    config = RewardConfig(closeness_weight=0.5)
    terms = reward_terms(config, vec(), np.zeros(L, int), vec(), np.zeros(L, int), np.array([0.0]))
    assert terms["closeness"] == pytest.approx(0.5)
    assert "closeness" not in reward_terms(
        RewardConfig(closeness_weight=0), vec(), np.zeros(L, int), vec(), np.zeros(L, int), np.array([0.0])
    )


def test_the_scripted_pianist_earns_more_than_an_idle_hand():
    from pianobot.env.piano import EnvConfig, PianoEnv
    from pianobot.music.piece import Note, Piece
    from pianobot.pianist.scripted import ScriptedPianist

    config = EnvConfig(tactile=False)
    env = PianoEnv(piece=Piece((Note(0.0, 64, 1.0, 80, 3),), bpm=60), config=config)
    totals = []
    for pianist in (ScriptedPianist(config), None):
        observation, _ = env.reset(seed=0)
        total = 0.0
        for _ in range(env.horizon):
            action = pianist.act(observation) if pianist else np.zeros(13)
            observation, reward, *_ = env.step(action)
            total += reward
        totals.append(total)
    assert totals[0] > totals[1] + 15  # the closeness bonus and the played note both count
