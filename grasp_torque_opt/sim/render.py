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
scale. The camera is chosen from a fixed list of views (:data:`VIEWS`) by small
segmentation renderings of each: the view that shows the most contacts' arrows
unhidden by the hand (the object is see-through; every contact where one exists), of
those the one whose arrows are least foreshortened and least on top of one another.
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
#: Arrows' middles this far apart across the line of sight count as apart [m].
SEPARATE = 0.02
#: The segmentation pass's object ids of the arrows: TAG + the contact's index.
TAG = 100000


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


def _draw_arrows(scene: mujoco.MjvScene, touching: list, predicted: list | None,
                 forward: np.ndarray, scale: float, tag: bool = False) -> None:
    """
    Add each touching contact's arrows to the scene, side by side across the line of sight.

    ``tag``: give each arrow the object id TAG + its contact's index (the segmentation
    pass's way of telling whose pixels are seen).
    """
    for i, r in touching:
        side = _across(r.force, forward) if predicted is not None else np.zeros(3)
        ends = [(r.position + side, r.position + side + scale * r.force, SIMULATED_RGBA)]
        if predicted is not None:
            ends.append((r.position - side, r.position - side + scale * predicted[i],
                         PREDICTED_RGBA))
        for start, end, rgba in ends:
            n = scene.ngeom
            _arrow(scene, start, end, rgba, 0.003)
            if tag and scene.ngeom > n:
                geom = scene.geoms[n]
                geom.segid, geom.objtype, geom.objid = n, mujoco.mjtObj.mjOBJ_UNKNOWN, TAG + i


def _apart(shown: list, forward: np.ndarray, scale: float) -> float:
    """Return the least distance between two arrows' middles across the line of sight [m]."""
    middles = [r.position + 0.5 * scale * r.force for r in shown]
    across = [m - (m @ forward) * forward for m in middles]
    return min((np.linalg.norm(a - b) for k, a in enumerate(across) for b in across[k + 1:]),
               default=SEPARATE)


def _pixels(renderer: mujoco.Renderer, hsim: HandSim, camera: mujoco.MjvCamera,
            touching: list, predicted: list | None, scale: float) -> np.ndarray:
    """Return, per touching contact, how many pixels of its arrows the camera sees."""
    forward = _forward(camera.azimuth, camera.elevation)
    renderer.update_scene(hsim.data, camera=camera)
    _draw_arrows(renderer.scene, touching, predicted, forward, scale, tag=True)
    seg = renderer.render()
    ids = seg[..., 0][seg[..., 1] == mujoco.mjtObj.mjOBJ_UNKNOWN]
    return np.array([np.count_nonzero(ids == TAG + i) for i, _ in touching])


def choose_view(hsim: HandSim, lookat: np.ndarray, touching: list, predicted: list | None,
                scale: float, distance: float) -> tuple[float, float, int]:
    """
    Return the view of :data:`VIEWS` that shows the most arrows, the least foreshortened.

    A contact is in view when at least half of its arrows' pixels show with the hand
    drawn (the object hidden), against the hand hidden too: two small segmentation
    renderings per view, exactly what the picture draws. Among the views that show the
    most contacts, the best by its worst of: the sine of the angle between an arrow and
    the line of sight (foreshortening), and the least distance between two arrows'
    middles across it over :data:`SEPARATE` (overlap); the first in :data:`VIEWS` on
    a tie.

    Args:
        hsim: the simulation, in the state to draw.
        lookat: the point looked at, world frame [m].
        touching: (index, reading) of the contacts that touch.
        predicted: the predicted forces, base axes [N], one per planned contact (or None).
        scale: arrow length per newton [m/N].
        distance: the camera's distance from ``lookat`` [m].

    Returns:
        Azimuth [deg], elevation [deg] and how many contacts it shows.
    """
    model = hsim.model
    rgba = model.geom_rgba.copy()
    hand = [g for g in range(model.ngeom) if model.geom_bodyid[g] != hsim.sim.object_body]
    renderer = mujoco.Renderer(model, 120, 160)
    renderer.enable_segmentation_rendering()
    best, key = (*VIEWS[0], 0), (-1, -1.0)
    try:
        camera = mujoco.MjvCamera()
        camera.lookat[:], camera.distance = lookat, distance
        for azimuth, elevation in VIEWS:
            camera.azimuth, camera.elevation = azimuth, elevation
            model.geom_rgba[:, 3] = np.where(model.geom_bodyid == hsim.sim.object_body, 0.0,
                                             rgba[:, 3])
            seen = _pixels(renderer, hsim, camera, touching, predicted, scale)
            model.geom_rgba[hand, 3] = 0.0
            alone = _pixels(renderer, hsim, camera, touching, predicted, scale)
            forward = _forward(azimuth, elevation)
            shown = [r for (_, r), s, a in zip(touching, seen, alone) if a > 0 and 2 * s >= a]
            quality = min([np.linalg.norm(np.cross(_unit(r.force), forward)) for r in shown]
                          + [_apart(shown, forward, scale) / SEPARATE])
            if (len(shown), quality) > key:
                key, best = (len(shown), quality), (azimuth, elevation, len(shown))
    finally:
        model.geom_rgba[:] = rgba
        renderer.close()
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
        lookat = hsim.data.xpos[hsim.sim.object_body].copy()
        azimuth, elevation, shown = choose_view(hsim, lookat, touching, predicted, scale,
                                                distance)
        camera = mujoco.MjvCamera()
        camera.lookat[:] = lookat
        camera.distance, camera.azimuth, camera.elevation = distance, azimuth, elevation
        renderer.update_scene(hsim.data, camera=camera)
        _draw_arrows(renderer.scene, touching, predicted, _forward(azimuth, elevation), scale)
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
