"""The inspection policy network of 004 Sec III-D (Fig 2).

Three inputs, encoded separately and joined (004 Fig 2):

* ``maps`` (B, 2, 21, 21, 21): the ego-centric occupancy map m^o and the spatial visit score map
  m^h (004 eq 3), into a 3D ResNet-style encoder. Without the SVS map (004 Table II) the encoder
  takes the occupancy channel only.
* ``depth`` (B, 1, 54, 96): the semantically masked depth image D_t(S_t), into a 2D ResNet-style
  encoder (IMPALA's, ref [31] of 004).
* ``state`` (B, 17): the robot state s_t and the previous action, concatenated as is with the two
  latent vectors.

The joined vector goes through an ELU MLP (2048-1024-512 in the paper), a GRU (512; none or 128
in 004 Table III) and two heads: the mean of a 4-D Gaussian action (its log standard deviation
is a learned vector independent of the input) and the state value.

Readings of the paper where it gives no number: each encoder ends with a linear layer to a
latent vector (``latent_size``), as Sample Factory's ResNet encoder does; every activation is
the configured one (ELU), IMPALA's included.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from typing import Literal, NamedTuple

import numpy as np
import torch
from pydantic import BaseModel, ConfigDict, Field
from torch import Tensor, nn

from seminspect.core.errors import InvalidInputError
from seminspect.missions.learning.env_config import ACTION_SIZE, STATE_SIZE, EnvConfig

#: Input shapes of one environment's observation with the default sensors (004 eq 4).
DEPTH_SHAPE = (1, EnvConfig().image_size[1], EnvConfig().image_size[0])
MAPS_SHAPE = (2, *(EnvConfig().map_cells,) * 3)
_SHAPES = {"state": (STATE_SIZE,), "depth": DEPTH_SHAPE, "maps": MAPS_SHAPE}

Observation = Mapping[str, Tensor]


class ConvStage(BaseModel):
    """One stage of a ResNet-style encoder: a convolution, an optional 3/2 max-pool (IMPALA),
    then ``blocks`` residual blocks of two 3-wide convolutions at the stage's width."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    channels: int = Field(gt=0)
    kernel: int = Field(3, gt=0)
    stride: int = Field(1, gt=0)
    pool: bool = False
    blocks: int = Field(0, ge=0)


def _impala_stages(channels: tuple[int, ...]) -> tuple[ConvStage, ...]:
    """IMPALA's stages (ref [31] of 004): 3x3 convolution, 3/2 max-pool, two residual blocks."""
    return tuple(ConvStage(channels=c, kernel=3, stride=1, pool=True, blocks=2) for c in channels)


class PolicyConfig(BaseModel):
    """Sizes of the network of 004 Fig 2; :meth:`paper` and :meth:`small` are the presets."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    map_stages: tuple[ConvStage, ...] = Field(min_length=1)
    depth_stages: tuple[ConvStage, ...] = Field(min_length=1)
    latent_size: int = Field(gt=0, description="each encoder's output vector")
    mlp_sizes: tuple[int, ...] = Field(min_length=1)
    gru_size: int = Field(ge=0, description="0: no GRU (004 Table III 'no GRU')")
    use_svs: bool = Field(True, description="False: the 3D encoder sees m^o only (Table II)")
    map_pool: int = Field(1, ge=1, description="max-pool the maps by this factor first")
    depth_pool: int = Field(1, ge=1, description="average-pool the depth image by this first")
    activation: Literal["elu"] = "elu"
    log_std_init: float = -0.5

    @classmethod
    def paper(cls, **changes: object) -> PolicyConfig:
        """004 Sec III-D: ResNet encoders, MLP 2048-1024-512 with ELU, GRU 512."""
        values: dict[str, object] = {
            "map_stages": _impala_stages((16, 32, 32)),
            "depth_stages": _impala_stages((16, 32, 32)),
            "latent_size": 512,
            "mlp_sizes": (2048, 1024, 512),
            "gru_size": 512,
        }
        return cls(**(values | changes))

    @classmethod
    def small(cls, **changes: object) -> PolicyConfig:
        """Sized to train on a 2-core CPU: pool the inputs by 3 (0.3 m map blocks, d_coll's
        size), one convolution per encoder, MLP 256-128, GRU 128. PyTorch's CPU 3D convolution
        is slow to train (bench/rl_policy.py): pooling first keeps the 3D encoder and cuts its
        cost several times."""
        values: dict[str, object] = {
            "map_stages": (ConvStage(channels=8, kernel=3, stride=1),),
            "depth_stages": (ConvStage(channels=16, kernel=3, stride=2),),
            "map_pool": 3,
            "depth_pool": 3,
            "latent_size": 64,
            "mlp_sizes": (256, 128),
            "gru_size": 128,
        }
        return cls(**(values | changes))


class PolicyOutput(NamedTuple):
    """What :meth:`InspectionPolicy.forward` returns for a (T, B) sequence."""

    mean: Tensor  # (T, B, 4) mean of the Gaussian action
    log_std: Tensor  # (4,) its log standard deviation
    value: Tensor  # (T, B) state value
    hidden: Tensor  # (B, gru_size) the recurrent state after the last step


class ActionSample(NamedTuple):
    """One step's decision for B environments (:meth:`InspectionPolicy.act`)."""

    action: Tensor  # (B, 4) clipped to [-1, 1]: what the environment receives
    raw_action: Tensor  # (B, 4) the Gaussian sample before clipping (its log-prob is kept)
    log_prob: Tensor  # (B,) log-probability of raw_action
    value: Tensor  # (B,)
    hidden: Tensor  # (B, gru_size)


def _activation(name: str) -> nn.Module:
    return {"elu": nn.ELU}[name]()


def _layer(module: nn.Conv2d | nn.Conv3d | nn.Linear, gain: float) -> nn.Module:
    """Orthogonal weights and zero bias (the usual PPO initialisation)."""
    nn.init.orthogonal_(module.weight, gain)
    if module.bias is not None:
        nn.init.zeros_(module.bias)
    return module


class _Residual(nn.Module):
    """``x + conv(act(conv(act(x))))`` at constant width (IMPALA's residual block)."""

    def __init__(self, conv: type[nn.Conv2d | nn.Conv3d], channels: int, activation: str):
        super().__init__()
        self.body = nn.Sequential(
            _activation(activation),
            _layer(conv(channels, channels, 3, padding=1), math.sqrt(2)),
            _activation(activation),
            _layer(conv(channels, channels, 3, padding=1), math.sqrt(2)),
        )

    def forward(self, x: Tensor) -> Tensor:
        return x + self.body(x)


class _BlockMax3d(nn.Module):
    """``nn.MaxPool3d(k)`` (stride k, no padding) as elementwise maxima of strided slices.

    The same numbers, about eight times faster on one CPU thread for the 21^3 maps: the
    outermost axis is reduced first, so each pass reads contiguous blocks.
    """

    def __init__(self, size: int):
        super().__init__()
        self.size = size

    def forward(self, x: Tensor) -> Tensor:
        k = self.size
        for axis in (-3, -2, -1):
            length = x.shape[axis] - x.shape[axis] % k
            parts = [
                x.narrow(axis, 0, length).unflatten(axis, (-1, k)).select(axis, i) for i in range(k)
            ]
            x = functools.reduce(torch.maximum, parts)
        return x


class ConvEncoder(nn.Module):
    """ResNet-style encoder for 2D images or 3D grids, ending in a latent vector."""

    def __init__(
        self,
        input_shape: tuple[int, ...],
        stages: tuple[ConvStage, ...],
        latent_size: int,
        activation: str,
        input_pool: int = 1,
    ):
        super().__init__()
        dims = len(input_shape) - 1
        conv = nn.Conv3d if dims == 3 else nn.Conv2d
        pool = nn.MaxPool3d if dims == 3 else nn.MaxPool2d
        # Maps keep "any obstacle in the block" (max); the depth image its mean range.
        first = _BlockMax3d if dims == 3 else nn.AvgPool2d
        self.input_pool = first(input_pool) if input_pool > 1 else nn.Identity()
        layers: list[nn.Module] = []
        channels = input_shape[0]
        for stage in stages:
            padding = stage.kernel // 2 if stage.stride == 1 else 0
            layers.append(
                _layer(conv(channels, stage.channels, stage.kernel, stage.stride, padding), 1.0)
            )
            if stage.pool:
                layers.append(pool(3, stride=2, padding=1))
            layers.extend(_Residual(conv, stage.channels, activation) for _ in range(stage.blocks))
            channels = stage.channels
        layers += [_activation(activation), nn.Flatten()]
        self.convs = nn.Sequential(*layers)
        with torch.no_grad():
            flat = self.convs(self.input_pool(torch.zeros(1, *input_shape))).shape[1]
        self.latent = nn.Sequential(
            _layer(nn.Linear(flat, latent_size), math.sqrt(2)), _activation(activation)
        )

    def forward(self, x: Tensor) -> Tensor:
        return self.latent(self.convs(self.input_pool(x)))


class InspectionPolicy(nn.Module):
    """Actor-critic of 004 Fig 2 over (T, B) sequences of observations.

    ``starts`` (T, B) marks the steps that begin a new episode: the recurrent state is zeroed
    before such a step, so a sequence may span episode boundaries (with same-step autoreset an
    environment's ``terminated | truncated`` at step t is ``starts`` at step t + 1).
    """

    def __init__(self, config: PolicyConfig):
        super().__init__()
        self.config = config
        act = config.activation
        map_channels = MAPS_SHAPE[0] if config.use_svs else 1
        self.map_encoder = ConvEncoder(
            (map_channels, *MAPS_SHAPE[1:]),
            config.map_stages,
            config.latent_size,
            act,
            input_pool=config.map_pool,
        )
        self.depth_encoder = ConvEncoder(
            DEPTH_SHAPE, config.depth_stages, config.latent_size, act, input_pool=config.depth_pool
        )
        layers: list[nn.Module] = []
        width = 2 * config.latent_size + STATE_SIZE
        for size in config.mlp_sizes:
            layers += [_layer(nn.Linear(width, size), math.sqrt(2)), _activation(act)]
            width = size
        self.mlp = nn.Sequential(*layers)
        self.gru = nn.GRUCell(width, config.gru_size) if config.gru_size else None
        head_width = config.gru_size or width
        self.action_mean = _layer(nn.Linear(head_width, ACTION_SIZE), 0.01)
        self.log_std = nn.Parameter(torch.full((ACTION_SIZE,), config.log_std_init))
        self.value_head = _layer(nn.Linear(head_width, 1), 1.0)

    def initial_state(self, batch: int) -> Tensor:
        """Zero recurrent state for ``batch`` environments, (batch, gru_size)."""
        return torch.zeros(batch, self.config.gru_size, device=self.log_std.device)

    def forward(self, obs: Observation, hidden: Tensor, starts: Tensor) -> PolicyOutput:
        """Run a (T, B) sequence: ``obs`` tensors (T, B, ...), ``hidden`` (B, H) before the
        first step, ``starts`` (T, B) 1.0 where an episode begins."""
        steps, batch = obs["state"].shape[:2]
        maps = obs["maps"].flatten(0, 1)
        if not self.config.use_svs:
            maps = maps[:, :1]
        joined = torch.cat(
            [
                self.map_encoder(maps),
                self.depth_encoder(obs["depth"].flatten(0, 1)),
                obs["state"].flatten(0, 1),
            ],
            dim=1,
        )
        features = self.mlp(joined).view(steps, batch, -1)
        if self.gru is not None:
            outputs = []
            for t in range(steps):
                hidden = self.gru(features[t], hidden * (1.0 - starts[t]).unsqueeze(1))
                outputs.append(hidden)
            features = torch.stack(outputs)
        mean = self.action_mean(features)
        value = self.value_head(features).squeeze(-1)
        return PolicyOutput(mean, self.log_std, value, hidden)

    @torch.no_grad()
    def act(
        self,
        obs: Observation,
        hidden: Tensor,
        starts: Tensor | None = None,
        deterministic: bool = False,
        generator: torch.Generator | None = None,
    ) -> ActionSample:
        """One step for B environments: ``obs`` tensors (B, ...), ``starts`` (B,) or None.

        The environment gets the sample clipped to [-1, 1]; the log-probability is that of the
        unclipped Gaussian sample, which is what PPO's ratio needs.
        """
        batch = obs["state"].shape[0]
        device = self.log_std.device
        step_starts = torch.zeros(1, batch, device=device) if starts is None else starts.view(1, -1)
        out = self({key: value.unsqueeze(0) for key, value in obs.items()}, hidden, step_starts)
        mean = out.mean[0]
        noise = (
            0.0 if deterministic else torch.randn(mean.shape, generator=generator, device=device)
        )
        raw = mean + out.log_std.exp() * noise
        log_prob = gaussian_log_prob(raw, mean, out.log_std)
        return ActionSample(raw.clamp(-1.0, 1.0), raw, log_prob, out.value[0], out.hidden)


def gaussian_log_prob(sample: Tensor, mean: Tensor, log_std: Tensor) -> Tensor:
    """Log-density of a diagonal Gaussian, summed over the last (action) dimension."""
    z = (sample - mean) * torch.exp(-log_std)
    per_dim = -0.5 * z.pow(2) - log_std - 0.5 * math.log(2 * math.pi)
    return per_dim.sum(-1)


def gaussian_entropy(log_std: Tensor) -> Tensor:
    """Entropy of a diagonal Gaussian with these log standard deviations."""
    return (log_std + 0.5 * math.log(2 * math.pi * math.e)).sum()


def as_tensors(
    obs: Mapping[str, np.ndarray], device: torch.device | str | None = None
) -> dict[str, Tensor]:
    """An environment's observation dict as float32 tensors (no copy on the CPU)."""
    check_observation(obs)
    return {key: torch.as_tensor(obs[key], dtype=torch.float32, device=device) for key in _SHAPES}


def check_observation(obs: Mapping[str, np.ndarray]) -> None:
    """Refuse an observation dict whose keys or shapes differ from the contract (004 eq 4)."""
    rows = set()
    for key, shape in _SHAPES.items():
        if key not in obs:
            raise InvalidInputError(f"observation has no {key!r} entry (found {sorted(obs)})")
        found = tuple(np.shape(obs[key]))
        if found[1:] != shape:
            expected = ", ".join(map(str, shape))
            raise InvalidInputError(
                f"observation {key!r} has shape {found}, expected (num_envs, {expected})"
            )
        rows.add(found[0])
    if len(rows) > 1:
        counts = {key: np.shape(obs[key])[0] for key in _SHAPES}
        raise InvalidInputError(f"observation entries differ in their number of envs: {counts}")
