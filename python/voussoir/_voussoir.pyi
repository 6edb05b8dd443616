"""Type stub of the native module (python/src). Use the wrappers in `voussoir` instead."""

from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np

__version__: str
WELD_TOLERANCE: float
REPAIR_TOLERANCE: float

class VoussoirError(ValueError): ...

class Mesh:
    def __init__(
        self,
        vertices: np.ndarray,
        faces: np.ndarray,
        anchored: np.ndarray,
        face_density: Optional[np.ndarray] = ...,
        extra_loads: Optional[np.ndarray] = ...,
        horizontal_forces: Optional[np.ndarray] = ...,
        prescribed_tau: Optional[np.ndarray] = ...,
        polygon_diagonals: Optional[np.ndarray] = ...,
    ) -> None: ...
    @staticmethod
    def read(
        path: str,
        supports: Optional[str],
        anchored: Optional[np.ndarray],
        weld_tolerance: Optional[float],
        repair_tolerance: float,
        anchor_boundary: bool = ...,
        anchor_lowest: Optional[float] = ...,
        anchor_lowest_absolute: bool = ...,
        up: str = ...,
        face_density: Optional[np.ndarray] = ...,
        extra_loads: Optional[np.ndarray] = ...,
        horizontal_forces: Optional[np.ndarray] = ...,
        prescribed_tau: Optional[np.ndarray] = ...,
    ) -> "Mesh": ...
    @property
    def vertices(self) -> np.ndarray: ...
    @property
    def faces(self) -> np.ndarray: ...
    @property
    def anchored(self) -> np.ndarray: ...
    @property
    def edges(self) -> np.ndarray: ...
    @property
    def welded_ids(self) -> np.ndarray: ...
    @property
    def polygon_diagonals(self) -> np.ndarray: ...
    @property
    def plan_repairs(self) -> List[str]: ...
    @property
    def n_holes(self) -> int: ...
    @property
    def face_density(self) -> np.ndarray: ...
    @property
    def extra_loads(self) -> np.ndarray: ...
    @property
    def horizontal_forces(self) -> np.ndarray: ...
    @property
    def prescribed_tau(self) -> np.ndarray: ...

def defaults() -> Dict[str, Any]: ...
def choices() -> Dict[str, List[str]]: ...
def analyse(
    mesh: Mesh, settings: Optional[Dict[str, Any]] = ..., report: bool = ...
) -> Dict[str, Any]: ...
def form_find(
    mesh: Mesh,
    settings: Optional[Dict[str, Any]] = ...,
    progress: Optional[Callable[[int, float], Optional[bool]]] = ...,
    report: bool = ...,
    start: Optional[Any] = ...,
) -> Dict[str, Any]: ...
def assess(
    mesh: Mesh,
    thickness: Optional[np.ndarray],
    intrados: Optional[Tuple[np.ndarray, np.ndarray]],
    extrados: Optional[Tuple[np.ndarray, np.ndarray]],
    settings: Dict[str, Any],
    progress: Optional[Callable[[int, float], Optional[bool]]] = ...,
    report: Optional[Tuple[Optional[str], Optional[str], Optional[str]]] = ...,
    springing: Optional[np.ndarray] = ...,
    reach: Optional[np.ndarray] = ...,
) -> Dict[str, Any]: ...
def min_thickness_of_family(
    mesh: Mesh,
    envelope_at: Callable[[float], Tuple[Optional[np.ndarray], ...]],
    thickness: float,
    scale_tolerance: float,
    settings: Dict[str, Any],
) -> Dict[str, Any]: ...
def write_mesh(mesh: Mesh, positions: np.ndarray, path: str) -> None: ...
