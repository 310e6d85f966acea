"""volref: the pure-CPU reference volume ray caster, from Python (docs/python.md).

Type stubs for the extension module volref.cpython-*.so (python/module.cpp).
"""
import os
from typing import Any, Literal, Mapping, Sequence, overload

import numpy as np
import numpy.typing as npt

__version__: str

Scene = str | os.PathLike[str] | Mapping[str, Any]
"""A scene file's path, JSON text (a str starting with '{'), or a dict in the scene format whose
volumes' "source" may be a 3-D numpy array indexed [k, j, i] (shape (nz, ny, nx), x fastest) of
dtype uint8, int8, uint16, int16, uint32, int32, float32 or float64."""

Overrides = Sequence[str] | Mapping[str, Any] | None
"""["render.step=0.25", ...] (the CLI's --set) or {"render.step": 0.25}."""

MemorySize = int | str | None
"""Bytes, or a size such as "4G" or "512MiB" (the CLI's --max-memory); None: the current limit."""

ImageInput = str | os.PathLike[str] | npt.NDArray[Any] | RenderResult

class Error(ValueError):
    """Bad input to volref: the one-line message names the file, scene key or argument at fault."""

class RenderResult:
    """What render returns: numpy views (no copy) of one float64 buffer, row 0 at the top."""

    @property
    def rgba(self) -> npt.NDArray[np.float64]:
        """(height, width, 4): premultiplied linear R, G, B, A (the CLI's EXR holds them as float32)."""
    @property
    def depth(self) -> npt.NDArray[np.float64] | None:
        """(height, width): first-hit depth (EXR channel Z, inf where no hit); None for other projections."""
    @property
    def error(self) -> npt.NDArray[np.float64] | None:
        """(height, width): each pixel's estimated error bound (error=True or the adaptive integrator), or None."""
    @property
    def pixels(self) -> npt.NDArray[np.float64]:
        """(height, width, len(channels)): every channel, as in the EXR."""
    @property
    def channels(self) -> list[str]:
        """The channel names: ['R', 'G', 'B', 'A'], then 'Z' (first-hit) and 'error' where present."""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def scene(self) -> dict[str, Any]:
        """The scene as volref resolved it: defaults filled in, overrides applied, file paths absolute,
        a numpy volume's source the array itself; no "camera" key for the default camera."""
    @property
    def non_finite_voxels(self) -> int:
        """NaN or infinite voxels in the volumes (rendered transparent; a RuntimeWarning says so)."""

def render(
    scene: Scene,
    *,
    threads: int | None = None,
    overrides: Overrides = None,
    error: bool = False,
    skipping: bool = True,
    max_memory: MemorySize = None,
) -> RenderResult:
    """Render a scene; the numbers of `volref render SCENE -o OUT.exr` (before the EXR's float32).

    threads: 1 to 4096, None = all cores (the image does not depend on it); overrides: the CLI's --set;
    error: add the step-doubling error estimate (.error, the CLI's --error); skipping: empty-space
    skipping (the image is the same); max_memory: the CLI's --max-memory for this call.
    Releases the GIL; Ctrl-C raises KeyboardInterrupt. Bad input raises volref.Error.
    """

def compare(
    a: ImageInput,
    b: ImageInput,
    *,
    tolerance: float | None = None,
    error: bool | npt.ArrayLike | tuple[npt.ArrayLike | None, npt.ArrayLike | None] | None = None,
    quantization: int | tuple[int | None, int | None] | None = None,
    background: Sequence[float] | None = None,
    max_memory: MemorySize = None,
) -> dict[str, Any]:
    """The JSON of `volref compare A B --json` as a dict (metrics per channel and overall, pixels over
    the tolerance, "within_tolerance"). Numpy inputs: (height, width, 4) premultiplied RGBA or
    (height, width, 3); float as is, uint8/uint16 scaled by 1/255, 1/65535 and counted as quantised.
    error=True adds each input's error channel (--tolerance-from-error), or give error arrays;
    quantization: the bits a numpy input was quantised to."""

@overload
def trace(
    scene: Scene,
    pixel: tuple[int, int],
    *,
    overrides: Overrides = None,
    skipping: bool = True,
    format: Literal["array"] = "array",
    max_memory: MemorySize = None,
) -> npt.NDArray[np.void]: ...
@overload
def trace(
    scene: Scene,
    pixel: tuple[int, int],
    *,
    overrides: Overrides = None,
    skipping: bool = True,
    format: Literal["json"],
    max_memory: MemorySize = None,
) -> dict[str, Any]: ...
def trace(
    scene: Scene,
    pixel: tuple[int, int],
    *,
    overrides: Overrides = None,
    skipping: bool = True,
    format: str = "array",
    max_memory: MemorySize = None,
) -> npt.NDArray[np.void] | dict[str, Any]:
    """Every sample of pixel (x, y)'s ray (`volref trace`): a structured array whose fields are the CSV
    columns of docs/trace.md (..., acc_r, acc_g, acc_b, acc_a); its last row is the pixel."""

def explain(topic: str, **arguments: Any) -> dict[str, Any]:
    """`volref explain TOPIC --json` as a dict; each keyword is the CLI option (underscores for dashes):
    explain("opacity-correction", opacity=0.5, length=0.25),
    explain("ray", scene="reference_scenes/levoy-lecture.json", pixel=(32, 32))."""
