"""BVHs built and traced on any Vulkan GPU, or on the CPU with the same kernels: closest hits
and occlusion queries for NumPy arrays of rays. See python/README.md."""
from typing import Literal, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Hits:
    """The closest hit of each of n rays."""

    t: npt.NDArray[np.float32]
    """(n,): distance along the normalized direction; inf for a miss."""
    primitive: npt.NDArray[np.int64]
    """(n,): the triangle hit (its row of `indices`); -1 for a miss."""
    instance: npt.NDArray[np.int64]
    """(n,): 0 for a hit, -1 for a miss."""
    barycentrics: npt.NDArray[np.float32]
    """(n, 2): of the triangle's second and third vertex (the point is
    (1 - b1 - b2) v0 + b1 v1 + b2 v2); 0 for a miss."""
    normal: npt.NDArray[np.float32]
    """(n, 3): the unit geometric normal, (v1 - v0) x (v2 - v0) normalized; 0 for a miss."""
    hit: npt.NDArray[np.bool_]
    """(n,): whether the ray hit anything."""
    def __len__(self) -> int: ...

class Tracer:
    """A BVH over a triangle mesh, on a GPU (Vulkan) or the CPU runner. On a GPU, queries release
    the GIL while the device works (the ray arrays must not change until they return).

    >>> import numpy as np, treelet
    >>> v = np.array([[0, 0, 5], [1, 0, 5], [0, 1, 5]], dtype=np.float32)
    >>> t = treelet.Tracer(v, np.array([[0, 1, 2]]), device="cpu")
    >>> hits = t.closest_hits(np.array([[0.2, 0.2, 0.0]]), np.array([[0.0, 0.0, 1.0]]))
    >>> float(hits.t[0]), int(hits.primitive[0])
    (5.0, 0)
    """

    def __init__(
        self,
        vertices: npt.ArrayLike,
        indices: npt.ArrayLike,
        device: Literal["auto", "gpu", "cpu"] = "auto",
        quality: Literal["fast", "balanced", "high"] = "fast",
    ) -> None:
        """Builds the tree over `vertices` ((v, 3) numbers) and `indices` ((m, 3) integers).
        Raises ValueError for a wrong shape, an index past the vertices or a coordinate that is
        not finite; TypeError for arrays that are not numbers (or indices not integers);
        RuntimeError where `device="gpu"` finds no Vulkan adapter."""
    @property
    def device(self) -> str:
        """The adapter's name, or "cpu"."""
    def __len__(self) -> int:
        """The number of triangles."""
    def closest_hits(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        t_min: Optional[Union[float, npt.ArrayLike]] = None,
        t_max: Optional[Union[float, npt.ArrayLike]] = None,
    ) -> Hits:
        """The closest hit of each ray origins[k] + t directions[k] ((n, 3) each; directions of
        any length, one of length 0 hitting nothing), from t_min (default 0) to t_max (default
        inf): numbers, or one per ray."""
    def occluded(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        t_min: Optional[Union[float, npt.ArrayLike]] = None,
        t_max: Optional[Union[float, npt.ArrayLike]] = None,
    ) -> npt.NDArray[np.bool_]:
        """Whether each ray hits anything from t_min up to t_max (inclusive)."""
    def refit(self, vertices: npt.ArrayLike, indices: npt.ArrayLike) -> None:
        """Moves the mesh (the same triangles, new vertices) and refits the tree's boxes."""
