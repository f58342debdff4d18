# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
One offscreen picture of the simulated grasp, contact forces drawn as arrows, with a legend.

Rendering is offscreen through EGL (``MUJOCO_GL=egl``, set by
:mod:`grasp_torque_opt.sim` unless already set): no display and no GPU needed,
Mesa's software EGL does. The PNG is written with Pillow.

At each contact the simulated force on the object is a blue arrow and the node's
predicted (certified) one a bright green arrow beside it, both opaque, of one
length per newton: blue is dark and green light, both far in hue from the orange
object (:data:`grasp_torque_opt.sim.model.OBJECT_RGBA`), and since the two agree
closely they are drawn side by side (each 2.5 mm off the contact point, across the
line of sight), not one inside the other. A legend in the picture names them and the
scale. The camera is chosen from a fixed list of views (:data:`VIEWS`) by rays cast
in the model: the view that shows the most contacts' arrows unhidden by the hand (the
object is see-through; every contact where one exists), of those the one that sees
its most foreshortened arrow most from the side.
"""

from __future__ import annotations

from pathlib import Path

from grasp_torque_opt.sim.simulator import HandSim
import mujoco
import numpy as np

#: Arrow colours: simulated force on the object (blue), certified (predicted) force
#: (bright green), both opaque.
SIMULATED_RGBA = np.array([0.1, 0.3, 1.0, 1.0], dtype=np.float32)
PREDICTED_RGBA = np.array([0.15, 1.0, 0.3, 1.0], dtype=np.float32)
#: The picture's caption: which arrow is which (the legend in the picture says it too).
CAPTION = "simulated contact forces blue, the node's predicted green beside them; legend inside"
#: The legend's lines: colour, words.
LEGEND = (
    (SIMULATED_RGBA, 'simulated contact force on the object (MuJoCo)'),
    (PREDICTED_RGBA, "predicted: the node's certified contact force"),
)
#: Camera views tried, (azimuth, elevation) [deg], in order of preference on a tie.
VIEWS = tuple((a, e) for e in (-20.0, -45.0, 10.0, -70.0, 40.0)
              for a in (-90.0, -60.0, -120.0, -30.0, -150.0, 0.0, 180.0, 30.0, 150.0,
                        60.0, 120.0, 90.0))
#: Arrows side by side: each this far off the contact point [m].
SIDE = 2.5e-3


class RenderUnavailable(RuntimeError):
    """No offscreen OpenGL context could be made (the reason is the message)."""


def write_png(path: str | Path, rgb: np.ndarray) -> None:
    """Write an RGB image, shape (h, w, 3) uint8, as PNG."""
    from PIL import Image

    Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8), 'RGB').save(Path(path), 'PNG')


def _arrow(scene: mujoco.MjvScene, start: np.ndarray, end: np.ndarray, rgba: np.ndarray,
           width: float) -> None:
    if scene.ngeom >= scene.maxgeom or np.linalg.norm(end - start) < 1e-6:
        return
    geom = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_ARROW, np.zeros(3), np.zeros(3),
                        np.eye(3).ravel(), rgba)
    mujoco.mjv_connector(geom, mujoco.mjtGeom.mjGEOM_ARROW, width, start, end)
    scene.ngeom += 1


def _forward(azimuth: float, elevation: float) -> np.ndarray:
    """Return the free camera's viewing direction, world axes (MuJoCo's convention)."""
    a, e = np.radians(azimuth), np.radians(elevation)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def _unit(v: np.ndarray) -> np.ndarray:
    return v / max(np.linalg.norm(v), 1e-12)


def _across(force: np.ndarray, forward: np.ndarray) -> np.ndarray:
    """Return the offset of the arrows drawn side by side: across the line of sight [m]."""
    return SIDE * _unit(np.cross(force, forward))


def _seen(hsim: HandSim, eye: np.ndarray, points: list[np.ndarray]) -> bool:
    """Return whether every point is seen from ``eye``, the object's body see-through."""
    geomid = np.zeros(1, dtype=np.int32)
    seen = 0
    for p in points:
        t = mujoco.mj_ray(hsim.model, hsim.data, eye, p - eye, None, 1,
                          hsim.sim.object_body, geomid)
        seen += t < 0 or t >= 0.999  # nothing before the point
    return seen == len(points)


def choose_view(hsim: HandSim, lookat: np.ndarray, arrows: list[tuple[np.ndarray, ...]],
                distance: float) -> tuple[float, float, int]:
    """
    Return the view of :data:`VIEWS` that shows the most arrows, the least foreshortened.

    Among the views that show the most contacts' arrows unhidden, the one whose most
    foreshortened arrow is seen at the largest angle to the line of sight (the first
    in :data:`VIEWS` on a tie).

    Args:
        hsim: the simulation, in the state to draw.
        lookat: the point looked at, world frame [m].
        arrows: per contact, (start, end) of its arrows' shared line, world frame [m].
        distance: the camera's distance from ``lookat`` [m].

    Returns:
        Azimuth [deg], elevation [deg] and how many contacts it shows.
    """
    best, key = (*VIEWS[0], 0), (-1, -1.0)
    for azimuth, elevation in VIEWS:
        forward = _forward(azimuth, elevation)
        eye = lookat - distance * forward
        sines = [np.linalg.norm(np.cross(_unit(b - a), forward)) for a, b in arrows
                 if _seen(hsim, eye, [a + s * _across(b - a, forward) + f * (b - a)
                                      for f in (0.1, 0.4, 0.7, 1.0) for s in (-2, 0, 2)])]
        if (len(sines), min(sines, default=0.0)) > key:
            key, best = (len(sines), min(sines, default=0.0)), (azimuth, elevation, len(sines))
    return best


def _legend(rgb: np.ndarray, lines: list[tuple[np.ndarray | None, str]]):
    """Return the picture with a legend box in its top left corner (a Pillow image)."""
    from PIL import Image, ImageDraw, ImageFont

    image = Image.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8), 'RGB')
    draw = ImageDraw.Draw(image)
    font = ImageFont.load_default(size=15)
    pad, row, swatch = 8, 22, 26
    width = max(draw.textlength(text, font=font) for _, text in lines) + swatch + 3 * pad
    draw.rectangle((4, 4, 4 + width, 4 + 2 * pad + row * len(lines) - 4), fill=(255, 255, 255),
                   outline=(90, 90, 90))
    for k, (rgba, text) in enumerate(lines):
        y = 4 + pad + row * k
        if rgba is not None:
            colour = tuple(int(255 * c) for c in rgba[:3])
            draw.line((4 + pad, y + 8, 4 + pad + swatch - 8, y + 8), fill=colour, width=6)
            draw.polygon([(4 + pad + swatch - 8, y + 1), (4 + pad + swatch, y + 8),
                          (4 + pad + swatch - 8, y + 15)], fill=colour)
        draw.text((4 + 2 * pad + swatch, y), text, fill=(0, 0, 0), font=font)
    return image


def render_grasp(hsim: HandSim, path: str | Path, predicted: list[np.ndarray] | None = None,
                 scale: float = 0.03, size: tuple[int, int] = (800, 600),
                 distance: float = 0.25) -> Path:
    """
    Render the grasp with its legend and write it as PNG.

    Args:
        hsim: the simulation, in the state to draw.
        path: the PNG to write.
        predicted: certified contact forces on the object, base axes [N], one per
            planned contact, drawn beside the simulated ones.
        scale: arrow length per newton [m/N].
        size: width and height [px].
        distance: the camera's distance from the object [m].

    Returns:
        The path written.

    Raises:
        RenderUnavailable: no offscreen OpenGL context (e.g. no EGL library).
    """
    model = hsim.model
    width, height = size
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    model.vis.headlight.ambient[:] = 0.4
    model.vis.headlight.diffuse[:] = 0.7
    try:
        renderer = mujoco.Renderer(model, height, width)
    except Exception as e:  # noqa: BLE001 -- whatever the GL backend raises, say why
        raise RenderUnavailable(f'{type(e).__name__}: {str(e).strip().splitlines()[0]}'
                                if str(e).strip() else type(e).__name__) from e
    geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == hsim.sim.object_body]
    alpha = model.geom_rgba[geoms, 3].copy()
    model.geom_rgba[geoms, 3] = 0.2  # see-through, so that the arrows inside show
    try:
        readings, _ = hsim.readings()
        touching = [(i, r) for i, r in enumerate(readings) if r.touching]
        # Each contact's arrows, from the contact into the object: the push it gets.
        arrows = [(r.position, r.position + scale * (r.force if predicted is None
                                                     else 0.5 * (r.force + predicted[i])))
                  for i, r in touching]
        lookat = hsim.data.xpos[hsim.sim.object_body].copy()
        azimuth, elevation, shown = choose_view(hsim, lookat, arrows, distance)
        camera = mujoco.MjvCamera()
        camera.lookat[:] = lookat
        camera.distance, camera.azimuth, camera.elevation = distance, azimuth, elevation
        renderer.update_scene(hsim.data, camera=camera)
        forward = _forward(azimuth, elevation)
        for i, r in touching:
            side = _across(r.force, forward) if predicted is not None else np.zeros(3)
            _arrow(renderer.scene, r.position + side, r.position + side + scale * r.force,
                   SIMULATED_RGBA, 0.003)
            if predicted is not None:
                _arrow(renderer.scene, r.position - side,
                       r.position - side + scale * predicted[i], PREDICTED_RGBA, 0.003)
        lines = [LEGEND[0]] + ([LEGEND[1]] if predicted is not None else [])
        lines.append((None, f'arrow length {1e3 * scale:g} mm per N; {shown} of '
                            f'{len(readings)} contacts in view'
                            + ('' if len(touching) == len(readings) else
                               f', {len(readings) - len(touching)} not touching')))
        _legend(renderer.render(), lines).save(Path(path), 'PNG')
    finally:
        model.geom_rgba[geoms, 3] = alpha
        renderer.close()
    return Path(path)
