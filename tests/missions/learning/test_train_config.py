"""The PPO hyper-parameters are validated and the curriculum read by fraction of training."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from seminspect.missions.learning.train_config import TrainConfig


def test_train_config_is_validated() -> None:
    with pytest.raises(ValidationError, match="multiple of minibatches"):
        TrainConfig(num_envs=6, minibatches=4)
    with pytest.raises(ValidationError, match="fractions must rise"):
        TrainConfig(curriculum=((0.5, 4), (0.2, 9)))
    with pytest.raises(ValidationError, match="fractions must rise"):
        TrainConfig(curriculum=((1.0, 4),))
    config = TrainConfig(curriculum=((0.1, 4), (0.5, 9)))
    assert [config.obstacles_at(f) for f in (0.0, 0.1, 0.49, 0.9)] == [None, 4, 4, 9]
