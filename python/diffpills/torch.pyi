# Type stubs for diffpills.torch.
from typing import Dict, Literal

import torch

from ._core import Contacts, Scene, Shape

def proximity(
    a: Shape,
    r_a: torch.Tensor,
    q_a: torch.Tensor,
    b: Shape,
    r_b: torch.Tensor,
    q_b: torch.Tensor,
    threads: int = 0,
    method: Literal["default", "interior_point"] = "default",
) -> torch.Tensor: ...
def signed_distance(
    a: Shape,
    r_a: torch.Tensor,
    q_a: torch.Tensor,
    b: Shape,
    r_b: torch.Tensor,
    q_b: torch.Tensor,
    threads: int = 0,
) -> torch.Tensor: ...
def scene_contacts(
    scene: Scene, r: torch.Tensor, q: torch.Tensor, margin: float = 0.0
) -> Contacts: ...
def shape_proximity(
    a: Dict[str, torch.Tensor],
    r_a: torch.Tensor,
    q_a: torch.Tensor,
    b: Dict[str, torch.Tensor],
    r_b: torch.Tensor,
    q_b: torch.Tensor,
    method: Literal["default", "interior_point"] = "default",
) -> torch.Tensor: ...
def shape_signed_distance(
    a: Dict[str, torch.Tensor],
    r_a: torch.Tensor,
    q_a: torch.Tensor,
    b: Dict[str, torch.Tensor],
    r_b: torch.Tensor,
    q_b: torch.Tensor,
) -> torch.Tensor: ...
