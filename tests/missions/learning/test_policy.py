"""The network of 004 Fig 2: shapes, recurrent resets, the Table II/III variants, actions."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch
from pydantic import ValidationError

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.policy import (
    DEPTH_SHAPE,
    MAPS_SHAPE,
    STATE_SIZE,
    InspectionPolicy,
    PolicyConfig,
    as_tensors,
)


def observations(steps: int, batch: int, seed: int = 0) -> dict[str, torch.Tensor]:
    generator = torch.Generator().manual_seed(seed)
    return {
        "state": torch.rand(steps, batch, STATE_SIZE, generator=generator),
        "depth": torch.rand(steps, batch, *DEPTH_SHAPE, generator=generator),
        "maps": torch.rand(steps, batch, *MAPS_SHAPE, generator=generator),
    }


def make_policy(config: PolicyConfig) -> InspectionPolicy:
    torch.manual_seed(0)
    return InspectionPolicy(config)


def test_small_preset_output_shapes() -> None:
    policy = make_policy(PolicyConfig.small())
    out = policy(observations(3, 5), policy.initial_state(5), torch.zeros(3, 5))
    assert out.mean.shape == (3, 5, 4)
    assert out.log_std.shape == (4,)
    assert out.value.shape == (3, 5)
    assert out.hidden.shape == (5, 128)


def test_paper_preset_is_the_network_of_sec_iii_d() -> None:
    policy = make_policy(PolicyConfig.paper())
    widths = [layer.out_features for layer in policy.mlp if isinstance(layer, torch.nn.Linear)]
    assert widths == [2048, 1024, 512]
    assert all(isinstance(layer, torch.nn.ELU) for layer in policy.mlp[1::2])
    assert policy.gru is not None and policy.gru.hidden_size == 512
    out = policy(observations(1, 2), policy.initial_state(2), torch.zeros(1, 2))
    assert out.mean.shape == (1, 2, 4) and out.value.shape == (1, 2)
    assert out.hidden.shape == (2, 512)


def test_a_start_resets_the_recurrent_state() -> None:
    policy = make_policy(PolicyConfig.small())
    obs = observations(4, 3)
    hidden = torch.randn(3, 128)
    starts = torch.zeros(4, 3)
    starts[2, 1] = 1.0  # env 1 begins a new episode at step 2
    through = policy(obs, hidden, starts)
    fresh = policy({k: v[2:] for k, v in obs.items()}, policy.initial_state(3), torch.zeros(2, 3))
    torch.testing.assert_close(through.mean[2:, 1], fresh.mean[:, 1])
    torch.testing.assert_close(through.value[2:, 1], fresh.value[:, 1])
    # the other envs carry their memory on: their outputs differ from a fresh start
    assert not torch.allclose(through.mean[2:, 0], fresh.mean[:, 0])


def test_the_gru_remembers_earlier_steps() -> None:
    policy = make_policy(PolicyConfig.small())
    obs = observations(2, 1)
    other = observations(2, 1, seed=1)
    other["state"][1] = obs["state"][1]
    other["depth"][1], other["maps"][1] = obs["depth"][1], obs["maps"][1]
    first = policy(obs, policy.initial_state(1), torch.zeros(2, 1))
    second = policy(other, policy.initial_state(1), torch.zeros(2, 1))
    assert not torch.allclose(first.mean[1], second.mean[1])


def test_without_a_gru_each_step_stands_alone() -> None:
    policy = make_policy(PolicyConfig.small(gru_size=0))
    assert policy.gru is None
    obs = observations(3, 2)
    out = policy(obs, policy.initial_state(2), torch.zeros(3, 2))
    assert out.hidden.shape == (2, 0)
    alone = policy({k: v[2:] for k, v in obs.items()}, policy.initial_state(2), torch.zeros(1, 2))
    torch.testing.assert_close(out.mean[2], alone.mean[0])


@pytest.mark.parametrize("size", [128, 512])
def test_gru_sizes_of_table_iii(size: int) -> None:
    policy = make_policy(PolicyConfig.small(gru_size=size))
    assert policy.initial_state(3).shape == (3, size)


def test_without_svs_the_visit_scores_are_ignored() -> None:
    obs = observations(1, 2)
    changed = {k: v.clone() for k, v in obs.items()}
    changed["maps"][:, :, 1] = 0.0
    blind = make_policy(PolicyConfig.small(use_svs=False))
    assert blind.map_encoder.convs[0].in_channels == 1
    outputs = [blind(o, blind.initial_state(2), torch.zeros(1, 2)).mean for o in (obs, changed)]
    torch.testing.assert_close(*outputs)
    seeing = make_policy(PolicyConfig.small())
    outputs = [seeing(o, seeing.initial_state(2), torch.zeros(1, 2)).mean for o in (obs, changed)]
    assert not torch.allclose(*outputs)


def test_actions_are_clipped_but_their_log_prob_is_the_gaussian_samples() -> None:
    policy = make_policy(PolicyConfig.small(log_std_init=1.0))  # wide: many samples leave [-1, 1]
    obs = {k: v[0] for k, v in observations(1, 64).items()}
    sample = policy.act(obs, policy.initial_state(64), generator=torch.Generator().manual_seed(3))
    assert sample.action.abs().max() <= 1.0
    assert (sample.raw_action.abs() > 1.0).any()
    torch.testing.assert_close(sample.action, sample.raw_action.clamp(-1, 1))
    out = policy({k: v[None] for k, v in obs.items()}, policy.initial_state(64), torch.zeros(1, 64))
    normal = torch.distributions.Normal(out.mean[0], out.log_std.exp())
    torch.testing.assert_close(sample.log_prob, normal.log_prob(sample.raw_action).sum(-1))
    torch.testing.assert_close(sample.value, out.value[0])


def test_deterministic_actions_are_the_clipped_mean() -> None:
    policy = make_policy(PolicyConfig.small())
    obs = {k: v[0] for k, v in observations(1, 4).items()}
    sample = policy.act(obs, policy.initial_state(4), deterministic=True)
    out = policy({k: v[None] for k, v in obs.items()}, policy.initial_state(4), torch.zeros(1, 4))
    torch.testing.assert_close(sample.action, out.mean[0].clamp(-1, 1))


def test_act_resets_the_state_of_starting_envs() -> None:
    policy = make_policy(PolicyConfig.small())
    obs = {k: v[0] for k, v in observations(1, 2).items()}
    hidden = torch.randn(2, 128)
    starts = torch.tensor([1.0, 0.0])
    reset = policy.act(obs, hidden, starts, deterministic=True)
    fresh = policy.act(obs, policy.initial_state(2), deterministic=True)
    torch.testing.assert_close(reset.hidden[0], fresh.hidden[0])
    assert not torch.allclose(reset.hidden[1], fresh.hidden[1])


def test_observations_from_numpy_are_checked() -> None:
    good = {
        "state": np.zeros((2, STATE_SIZE), np.float32),
        "depth": np.zeros((2, *DEPTH_SHAPE), np.float32),
        "maps": np.zeros((2, *MAPS_SHAPE), np.float32),
    }
    assert as_tensors(good)["maps"].shape == (2, *MAPS_SHAPE)
    with pytest.raises(InvalidInputError, match="no 'depth' entry"):
        as_tensors({k: v for k, v in good.items() if k != "depth"})
    with pytest.raises(InvalidInputError, match="'maps' has shape"):
        as_tensors(good | {"maps": np.zeros((2, 1, 21, 21, 21), np.float32)})
    with pytest.raises(InvalidInputError, match="differ in their number of envs"):
        as_tensors(good | {"state": np.zeros((3, STATE_SIZE), np.float32)})


def test_configs_are_validated_and_frozen() -> None:
    with pytest.raises(ValidationError):
        PolicyConfig.small(gru_size=-1)
    with pytest.raises(ValidationError):
        PolicyConfig.small(mlp_sizes=())
    with pytest.raises(ValidationError):
        PolicyConfig.small(dropout=0.1)
    config = PolicyConfig.small()
    with pytest.raises(ValidationError):
        config.gru_size = 3  # type: ignore[misc]
    assert PolicyConfig.model_validate(config.model_dump(mode="json")) == config


def test_the_small_preset_is_small() -> None:
    small = make_policy(PolicyConfig.small())
    paper = make_policy(PolicyConfig.paper())
    count = lambda policy: sum(p.numel() for p in policy.parameters())  # noqa: E731
    assert count(small) < 1_000_000
    assert count(paper) > 5_000_000
    assert math.isclose(small.log_std.exp()[0].item(), math.exp(-0.5), rel_tol=1e-6)


def test_importing_the_package_does_not_load_torch() -> None:
    code = "import sys, seminspect.missions.learning; assert 'torch' not in sys.modules"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[3] / "src")}
    subprocess.run([sys.executable, "-c", code], check=True, env=env)


def test_small_preset_pools_its_inputs_before_convolving() -> None:
    from seminspect.missions.learning.policy import _BlockMax3d

    small = make_policy(PolicyConfig.small())
    assert isinstance(small.map_encoder.input_pool, _BlockMax3d)
    assert isinstance(small.depth_encoder.input_pool, torch.nn.AvgPool2d)
    # A single occupied cell survives the max-pool of the maps: the encoder's output moves.
    empty = torch.zeros(1, *MAPS_SHAPE)
    one = empty.clone()
    one[0, 0, 10, 10, 10] = 1.0
    with torch.no_grad():
        assert not torch.equal(small.map_encoder(empty), small.map_encoder(one))
    paper = make_policy(PolicyConfig.paper())
    assert isinstance(paper.map_encoder.input_pool, torch.nn.Identity)


@pytest.mark.parametrize("shape", [(2, 2, 21, 21, 21), (1, 1, 22, 20, 23)])
def test_block_max_is_max_pool_with_its_gradient(shape) -> None:
    from seminspect.missions.learning.policy import _BlockMax3d

    x = torch.rand(*shape, generator=torch.Generator().manual_seed(1), requires_grad=True)
    reference = torch.nn.MaxPool3d(3)(x)
    ours = _BlockMax3d(3)(x)
    assert torch.equal(ours, reference)
    (grad_ours,) = torch.autograd.grad(ours.sum(), x)
    (grad_reference,) = torch.autograd.grad(reference.sum(), x)
    assert torch.equal(grad_ours, grad_reference)
