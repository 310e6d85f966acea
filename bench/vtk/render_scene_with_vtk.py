#!/usr/bin/python3
"""Renders a volref scene file with one of VTK 9.1's volume mappers, for the parity test.

    xvfb-run -a -s "-screen 0 640x480x24" /usr/bin/python3 bench/vtk/render_scene_with_vtk.py \
        SCENE.json --mapper gpu -o OUT.png

--mapper gpu: vtkGPUVolumeRayCastMapper (its GLSL on Mesa llvmpipe here); --mapper fixed:
vtkFixedPointVolumeRayCastMapper. Same volume, transfer functions, camera, light and sample distance
as the scene says, with VTK's traps set off: linear interpolation (VTK's default is nearest),
AutoAdjustSampleDistances off (it ignores SampleDistance otherwise), no jittering, one ray per pixel.
The image is written as an 8-bit RGB PNG over the scene's (opaque) background.

Supported (anything else is an error): a volume file in NRRD (attached, raw encoding, float, as
scripts/vtk-parity.sh writes it) or volref's marschner-lobb field; volume.origin and .spacing;
a data-domain transfer function without gradient opacity; optional Blinn-Phong shading with one
white headlight, two-sided (VTK's renderer default); a perspective camera; projections composite,
mip, minip and average (the fixed-point mapper renders composite, mip and minip only).
"""
import argparse
import json
import os
import sys

import numpy as np

import vtkmodules.vtkRenderingOpenGL2  # noqa: F401
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401
from vtkmodules.util import numpy_support
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkRenderingCore import vtkLight, vtkRenderer, vtkRenderWindow, vtkVolume, vtkWindowToImageFilter
from vtkmodules.vtkRenderingVolume import vtkFixedPointVolumeRayCastMapper, vtkGPUVolumeRayCastMapper

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vtk_render import build_property, marschner_lobb  # noqa: E402  (the comparison's own code)


def fail(message):
    sys.exit("render_scene_with_vtk.py: " + message)


def read_nrrd(path):
    """A float, unsigned char or unsigned short NRRD with an attached raw little-endian body: returns
    (dims, values (nz, ny, nx)) in the file's type."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"\n\n")
    fields = {}
    for line in data[:end].decode("ascii").splitlines()[1:]:
        if ":" in line and not line.startswith("#"):
            k, v = line.split(":", 1)
            fields[k.strip()] = v.strip()
    types = {"float": "<f4", "uchar": "u1", "unsigned char": "u1", "ushort": "<u2", "unsigned short": "<u2"}
    if fields.get("type") not in types or fields.get("encoding") != "raw" or fields.get("endian", "little") != "little":
        fail(f"{path}: only float, uchar and ushort, raw, little-endian NRRD files are supported")
    dims = [int(x) for x in fields["sizes"].split()]
    values = np.frombuffer(data[end + 2:], dtype=types[fields["type"]], count=dims[0] * dims[1] * dims[2])
    return dims, values.reshape(dims[2], dims[1], dims[0])


def build_volume(scene, scene_dir):
    vs = scene["volume"]
    src = vs["source"]
    if isinstance(src, str):
        dims, values = read_nrrd(os.path.join(scene_dir, src))
    elif isinstance(src, dict) and src.get("field") == "marschner-lobb":
        dims = src.get("dims", [2, 2, 2])
        values = marschner_lobb(dims, src.get("fm", 6.0), src.get("alpha", 0.25))
    else:
        fail("volume.source: a .nrrd file or the marschner-lobb field")
    image = vtkImageData()
    image.SetDimensions(*dims)
    image.SetOrigin(*vs.get("origin", [0, 0, 0]))
    image.SetSpacing(*vs.get("spacing", [1, 1, 1]))
    array = numpy_support.numpy_to_vtk(np.ascontiguousarray(values).ravel(), deep=True)
    array.SetName("scalars")
    image.GetPointData().SetScalars(array)
    return image


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--mapper", choices=["gpu", "fixed"], required=True)
    ap.add_argument("-o", "--output", required=True)
    args = ap.parse_args()
    with open(args.scene) as f:
        scene = json.load(f)
    image = build_volume(scene, os.path.dirname(os.path.abspath(args.scene)))
    prop, shading, keep = build_property(scene)
    render = scene.get("render", {})
    spacing = min(scene["volume"].get("spacing", [1, 1, 1]))
    step = render.get("step", 0.5) * (spacing if render.get("step_units", "voxel") == "voxel" else 1.0)

    if args.mapper == "fixed":
        mapper = vtkFixedPointVolumeRayCastMapper()
        mapper.SetImageSampleDistance(1.0)
        mapper.SetMinimumImageSampleDistance(1.0)
        mapper.SetInteractiveSampleDistance(step)
    else:
        mapper = vtkGPUVolumeRayCastMapper()
        mapper.SetUseJittering(0)
    mapper.SetInputData(image)
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetSampleDistance(step)
    projection = render.get("projection", "composite")
    modes = {"composite": mapper.SetBlendModeToComposite, "mip": mapper.SetBlendModeToMaximumIntensity,
             "minip": mapper.SetBlendModeToMinimumIntensity, "average": mapper.SetBlendModeToAverageIntensity}
    if projection not in modes or (args.mapper == "fixed" and projection == "average"):
        fail(f"render.projection {projection!r} is not rendered by the {args.mapper} mapper")
    modes[projection]()

    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    img = scene.get("image", {})
    width, height = img.get("width", 256), img.get("height", 256)
    bg = img.get("background", [0, 0, 0, 0])
    ren = vtkRenderer()
    ren.SetBackground(bg[0] * bg[3], bg[1] * bg[3], bg[2] * bg[3])
    ren.AddVolume(volume)
    if shading is not None:
        light = vtkLight()
        light.SetLightTypeToHeadlight()
        light.SetIntensity(1.0)
        light.SetAmbientColor(1.0, 1.0, 1.0)
        light.SetDiffuseColor(1.0, 1.0, 1.0)
        light.SetSpecularColor(1.0, 1.0, 1.0)
        ren.AddLight(light)
    rw = vtkRenderWindow()
    rw.SetOffScreenRendering(1)
    rw.SetMultiSamples(0)
    rw.SetSize(width, height)
    rw.AddRenderer(ren)
    cam_spec = scene["camera"]
    if cam_spec.get("type") != "perspective":
        fail("only perspective cameras are supported")
    cam = ren.GetActiveCamera()
    cam.SetPosition(*cam_spec.get("eye", [0, 0, 1]))
    cam.SetFocalPoint(*cam_spec.get("target", [0, 0, 0]))
    cam.SetViewUp(*cam_spec.get("up", [0, 1, 0]))
    cam.OrthogonalizeViewUp()
    cam.SetViewAngle(cam_spec.get("fov_y", 30))
    ren.ResetCameraClippingRange()
    rw.Render()
    rw.WaitForCompletion()
    w2i = vtkWindowToImageFilter()
    w2i.SetInput(rw)
    w2i.SetInputBufferTypeToRGB()
    w2i.ReadFrontBufferOff()
    w2i.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(args.output)
    writer.SetInputConnection(w2i.GetOutputPort())
    writer.Write()


if __name__ == "__main__":
    main()
