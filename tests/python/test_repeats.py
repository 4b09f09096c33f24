"""evaluation.repeats and evaluation.repeat_perturbation through Python: the keys round-trip through
the config, bad values name the key, and animat.evaluate reports fitness_spread (0 for one swim)."""

import pickle

import pytest

import animat


class DistanceSeen(list):
    """A Python objective that scores the distance and keeps every value it was asked for."""

    name = "distance_seen"
    every = 0

    def __call__(self, record):
        self.append(record.result.fitness)
        return record.result.fitness


def small_config(**evaluation):
    c = animat.Config()
    c["evaluation.steps"] = 300
    for key, value in evaluation.items():
        c[f"evaluation.{key}"] = value
    return c


def test_the_keys_default_to_one_swim_and_round_trip():
    c = animat.Config()
    assert c["evaluation.repeats"] == 1
    assert c["evaluation.repeat_perturbation"] == 1e-6
    c["evaluation.repeats"] = 3
    c.evaluation.repeat_perturbation = 1e-5
    assert c.evaluation.repeats == 3
    back = animat.Config.from_toml(c.to_toml())
    assert back["evaluation.repeats"] == 3
    assert back["evaluation.repeat_perturbation"] == 1e-5
    assert back == c
    assert animat.Config(c.to_dict())["evaluation.repeats"] == 3
    assert pickle.loads(pickle.dumps(c))["evaluation.repeat_perturbation"] == 1e-5
    # Both are documented like every key.
    text = animat.Config().to_toml()
    assert "repeats = 1" in text and "repeat_perturbation = " in text


@pytest.mark.parametrize(
    "key, value",
    [
        ("evaluation.repeats", 0),
        ("evaluation.repeats", 65),
        ("evaluation.repeat_perturbation", 0.0),
        ("evaluation.repeat_perturbation", 0.5),
        ("evaluation.repeat_perturbation", float("nan")),
    ],
)
def test_bad_values_name_the_key_and_the_value(key, value):
    c = animat.Config()
    with pytest.raises(ValueError) as e:
        c[key] = value
    assert key in str(e.value), str(e.value)
    assert "out of range" in str(e.value) or "finite" in str(e.value), str(e.value)


def test_fitness_spread_is_zero_for_one_swim_and_the_spread_of_several():
    genome, _ = animat.Genome.random_viable(seed=3, config=small_config())
    one = animat.evaluate(genome, small_config())
    assert one.fitness_spread == 0.0
    assert one.to_dict()["fitness_spread"] == 0.0
    three = animat.evaluate(genome, small_config(repeats=3, repeat_perturbation=1e-3))
    assert three.valid
    assert three.fitness_spread >= 0.0
    # The diagnostics are repeat 0's: the unperturbed swim's.
    assert list(three.displacement) == list(one.displacement)
    back = pickle.loads(pickle.dumps(three))
    assert back.fitness == three.fitness and back.fitness_spread == three.fitness_spread
    # A Python objective scores every repeat; the fitness is the mean of its values.
    seen = DistanceSeen()
    scored = animat.evaluate(genome, small_config(repeats=3, repeat_perturbation=1e-3), objective=seen)
    assert len(seen) == 3
    assert seen[0] == one.fitness
    assert scored.fitness == sum(seen) / 3 == three.fitness


def test_the_min_statistic_is_the_worst_repeat_and_an_unknown_one_is_refused():
    genome, _ = animat.Genome.random_viable(seed=3, config=small_config())
    seen = DistanceSeen()
    worst = small_config(repeats=3, repeat_perturbation=1e-3, repeat_statistic="min")
    assert animat.Config.from_toml(worst.to_toml())["evaluation.repeat_statistic"] == "min"
    scored = animat.evaluate(genome, worst, objective=seen)
    assert len(seen) == 3
    assert scored.fitness == min(seen) == animat.evaluate(genome, worst).fitness
    c = animat.Config()
    assert c["evaluation.repeat_statistic"] == "mean"
    with pytest.raises(ValueError) as e:
        c["evaluation.repeat_statistic"] = "median"
    assert "evaluation.repeat_statistic" in str(e.value) and "median" in str(e.value), str(e.value)
