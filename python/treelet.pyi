"""BVHs built and traced on any Vulkan GPU, or on the CPU with the same kernels: closest hits
and occlusion queries for NumPy arrays of rays. See python/README.md."""
from typing import Literal, Optional, Sequence, Tuple, Union

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
    """(n,): the instance hit (0 for a Tracer's hits); -1 for a miss."""
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
        out: Optional[Hits] = None,
    ) -> Hits:
        """The closest hit of each ray origins[k] + t directions[k] ((n, 3) each; directions of
        any length, one of length 0 hitting nothing), from t_min (default 0) to t_max (default
        inf): numbers, or one per ray. out, the Hits of an earlier batch of as many rays, is
        filled in place and returned."""
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

class InstancedTracer:
    """Meshes placed many times by transforms (a tree per mesh, a top-level tree over the
    instances), on a GPU (Vulkan) or the CPU runner. A hit names its instance and the triangle
    within that instance's mesh. On a GPU, queries release the GIL while the device works.

    >>> import numpy as np, treelet
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
    >>> moved = np.array([[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, z]] for z in (5, 9)], dtype=np.float32)
    >>> s = treelet.InstancedTracer([(v, np.array([[0, 1, 2]]))], np.array([0, 0]), moved, device="cpu")
    >>> hits = s.closest_hits(np.array([[0.2, 0.2, 0.0]]), np.array([[0.0, 0.0, 1.0]]))
    >>> float(hits.t[0]), int(hits.instance[0]), int(hits.primitive[0])
    (5.0, 0, 0)
    """

    def __init__(
        self,
        meshes: Sequence[Tuple[npt.ArrayLike, npt.ArrayLike]],
        mesh: npt.ArrayLike,
        transforms: npt.ArrayLike,
        device: Literal["auto", "gpu", "cpu"] = "auto",
        quality: Literal["fast", "balanced", "high"] = "fast",
    ) -> None:
        """Builds a tree for each of `meshes` ((vertices, indices) pairs, as Tracer takes them)
        and the top-level tree: instance i is mesh `mesh[i]` ((k,) integers) placed by
        `transforms[i]` ((k, 3, 4) or (k, 4, 4), row-major: a point p goes to T @ [p, 1]).
        Raises ValueError for a mesh index out of range, a transform that is not finite or
        projective, or mismatched counts; TypeError for arguments of the wrong kind."""
    @property
    def device(self) -> str:
        """The adapter's name, or "cpu"."""
    def __len__(self) -> int:
        """The number of instances."""
    def closest_hits(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        t_min: Optional[Union[float, npt.ArrayLike]] = None,
        t_max: Optional[Union[float, npt.ArrayLike]] = None,
        out: Optional[Hits] = None,
    ) -> Hits:
        """As Tracer.closest_hits (out included): `instance` is the instance hit, `primitive` the
        triangle within its mesh, `normal` in world space."""
    def occluded(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        t_min: Optional[Union[float, npt.ArrayLike]] = None,
        t_max: Optional[Union[float, npt.ArrayLike]] = None,
    ) -> npt.NDArray[np.bool_]:
        """Whether each ray hits anything from t_min up to t_max (inclusive)."""
    def set_instances(self, mesh: npt.ArrayLike, transforms: npt.ArrayLike) -> None:
        """Places the instances anew (any number, of the same meshes); only the top level is
        rebuilt."""
    def refit_mesh(self, index: int, vertices: npt.ArrayLike, indices: npt.ArrayLike) -> None:
        """Moves mesh `index` (the same triangles, new vertices) and refits its tree; every
        instance of it moves with it."""

def render(
    scene: str = "cornell",
    width: int = 512,
    height: int = 384,
    spp: int = 16,
    seed: int = 0,
    integrator: Literal["nee", "smallpt", "caustics"] = "nee",
    sampler: Literal["sobol", "independent"] = "sobol",
    accel: Literal["auto", "none", "lbvh", "hploc", "trbvh"] = "auto",
    device: Literal["auto", "gpu", "cpu"] = "auto",
) -> npt.NDArray[np.float32]:
    """Renders `scene` (what `treelet render --scene` takes: "cornell", "room_disk", "terrain:N",
    "city:N", a .json scene file, a .gltf/.glb scene or an .obj/.ply mesh) and returns the linear
    HDR image, (height, width, 3) float32, row 0 at the top. On a GPU the GIL is released while it
    renders. Raises ValueError for a bad argument or scene, RuntimeError where the device fails.

    >>> import treelet
    >>> image = treelet.render("cornell", 32, 24, spp=4, device="cpu")
    >>> image.shape, bool(image.mean() > 0)
    ((24, 32, 3), True)
    """
