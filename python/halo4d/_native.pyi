"""Type stubs of halo4d's native module (re-exported by `halo4d`)."""

import os
from typing import Any, Callable, Literal, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

SceneSource = Union[dict[str, Any], str, "os.PathLike[str]", None]
View = Optional[dict[str, Any]]
Progress = Optional[Callable[[dict[str, Any]], None]]
"""Called with each event of the work: a dict whose `kind` is "begin" (with `task` and
`steps`), "doing" (`text`), "done" (`done`), "end", "warning" or "note" (`text`)."""

class SceneError(ValueError):
    """A scene that is not valid; the message is the command line's."""

    field: Optional[str]
    """The path of the field at fault (`surfaces[0].surface.n`), None when unreadable."""
    file: str
    """The scene's source: its file, `<dict>` or `<json>`."""

class BuildError(RuntimeError):
    """A build, picture or write that failed; the message is the command line's."""

class Scene:
    """A scene, validated as `halo4d build` validates a scene file.

    `Scene()` is the default scene; `Scene(source)` takes a dict, a JSON string or the path
    of a scene file.
    """

    def __init__(self, source: SceneSource = None) -> None: ...
    @property
    def name(self) -> str: ...
    def to_json(self) -> str: ...
    def to_dict(self) -> dict[str, Any]: ...
    def sample(self, progress: Progress = None) -> Sampled:
        """Samples the surfaces in 4D once, to build any number of views."""
    def build(self, view: View = None, progress: Progress = None) -> Built:
        """Samples and builds the scene in `view` (a scene file's `view`), nothing written."""

class Sampled:
    """A scene's surfaces sampled in 4D."""

    def build(self, view: View = None, scene: Optional[Scene] = None, progress: Progress = None) -> Built:
        """Builds in `view`; `scene`: another scene of the same surfaces and sampling."""
    @property
    def triangles(self) -> int: ...

class Built:
    """A scene built in one 4D view."""

    @property
    def scene(self) -> Scene: ...
    @property
    def verified(self) -> bool: ...
    @property
    def failures(self) -> list[str]: ...
    @property
    def surfaces(self) -> list[Surface]: ...
    @property
    def curves(self) -> list[Curve]: ...
    @property
    def triple_points(self) -> npt.NDArray[np.float64]:
        """(n, 3)."""
    @property
    def report(self) -> dict[str, Any]: ...
    def write(self, dir: Union[str, "os.PathLike[str]"], progress: Progress = None) -> dict[str, Any]:
        """Writes the scene's outputs into `dir`; the report."""
    def render(
        self,
        width: Optional[int] = None,
        height: Optional[int] = None,
        style: Optional[Literal["shaded", "stipple"]] = None,
        samples: Optional[int] = None,
    ) -> npt.NDArray[np.uint8]:
        """The picture, (height, width, 3) sRGB."""
    def glb(self) -> bytes: ...

class Surface:
    """One surface of a build."""

    @property
    def name(self) -> str: ...
    @property
    def vertices4d(self) -> npt.NDArray[np.float64]:
        """(n, 4)."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(n, 3), projected, rounded to f32 as the files store them."""
    @property
    def w(self) -> npt.NDArray[np.float64]:
        """(n,)."""
    @property
    def normals(self) -> npt.NDArray[np.float64]:
        """(n, 3)."""
    @property
    def triangles(self) -> npt.NDArray[np.uint32]:
        """(m, 3)."""
    @property
    def halo(self) -> Optional[Halo]: ...

class Halo:
    """A surface's volumetric halo."""

    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """(k, 3)."""
    @property
    def tetrahedra(self) -> npt.NDArray[np.uint32]:
        """(t, 4), in the files' (VTK's) order: det[b - a, c - a, d - a] > 0."""
    @property
    def t(self) -> npt.NDArray[np.float64]:
        """(k,)."""
    @property
    def d_orig(self) -> npt.NDArray[np.float64]:
        """(k,)."""
    @property
    def surface_vertices(self) -> int: ...

class Curve:
    """A self-intersection curve."""

    @property
    def points(self) -> npt.NDArray[np.float64]:
        """(p, 3)."""
    @property
    def w(self) -> npt.NDArray[np.float64]:
        """(p, 2)."""
    @property
    def sheets(self) -> npt.NDArray[np.uint32]:
        """(p, 2)."""
    @property
    def over(self) -> npt.NDArray[np.uint8]:
        """(p,)."""
    @property
    def closed(self) -> bool: ...
    @property
    def ends(self) -> list[str]: ...
    def __len__(self) -> int: ...

def catalogue() -> list[dict[str, Any]]: ...
def check(path: Union[str, "os.PathLike[str]"]) -> dict[str, Any]: ...
def certify_arrays(points: Any, tets: Any, solids: Any, name: str, format: str) -> dict[str, Any]: ...
