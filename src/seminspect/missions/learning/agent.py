"""The trained policy as a :class:`~seminspect.missions.learning.baselines.Controller`, and the
shipped one.

The package ships one checkpoint of the small configuration (``data/rl/policy.pt``), trained on
a 2-core CPU with the command and budget given in docs/learning.md; with no path,
:func:`load_controller` uses it.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np
import torch
from numpy.typing import NDArray

from seminspect.missions.learning.checkpoints import read_checkpoint
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import InspectionPolicy, as_tensors

#: The checkpoint inside the package: (package, relative path).
SHIPPED_POLICY = ("seminspect", "data/rl/policy.pt")


def shipped_policy_path() -> Path:
    """Where the package's trained checkpoint lies."""
    package, relative = SHIPPED_POLICY
    return Path(str(resources.files(package).joinpath(relative)))


class LearnedController:
    """Drive rooms with a trained :class:`InspectionPolicy` (mean action, no sampling).

    The recurrent state is kept per room and cleared at :meth:`reset`. ``env_config`` is the
    environment the policy was trained in (its checkpoint's): what it should be flown in.
    """

    def __init__(
        self, policy: InspectionPolicy, env_config: EnvConfig, *, deterministic: bool = True
    ) -> None:
        self.policy = policy.eval()
        self.env_config = env_config
        self.deterministic = deterministic
        self._hidden = policy.initial_state(0)
        self._generator = torch.Generator().manual_seed(0)

    def reset(self, env: InspectionVectorEnv) -> None:
        self._hidden = self.policy.initial_state(env.num_envs)
        self._generator = torch.Generator().manual_seed(0)

    def act(self, env: InspectionVectorEnv, obs: dict[str, NDArray[np.float32]]) -> NDArray:
        sample = self.policy.act(
            as_tensors(obs),
            self._hidden,
            deterministic=self.deterministic,
            generator=self._generator,
        )
        self._hidden = sample.hidden
        return sample.action.numpy()


def load_controller(path: Path | None = None) -> LearnedController:
    """The controller of a checkpoint file, or of the shipped policy when ``path`` is None."""
    checkpoint = read_checkpoint(shipped_policy_path() if path is None else path)
    return LearnedController(checkpoint.policy, checkpoint.env_config)
