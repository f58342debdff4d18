# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""
One offscreen picture of the simulated grasp, contact forces drawn as arrows.

Rendering is offscreen through EGL (``MUJOCO_GL=egl``, set by
:mod:`grasp_torque_opt.sim` unless already set): no display and no GPU needed,
Mesa's software EGL does. The PNG is written with Pillow.

The simulated forces are blue and the predicted ones a see-through green, both far
in hue from the orange object (:data:`grasp_torque_opt.sim.model.OBJECT_RGBA`), so
the arrows show against it; :data:`CAPTION` says so wherever the picture is named.
"""

from __future__ import annotations

from pathlib import Path

from grasp_torque_opt.sim.simulator import HandSim
import mujoco
import numpy as np

#: Arrow colours: simulated force on the object (blue), certified (predicted) force
#: (see-through green).
SIMULATED_RGBA = np.array([0.15, 0.55, 1.0, 1.0], dtype=np.float32)
PREDICTED_RGBA = np.array([0.1, 0.8, 0.2, 0.25], dtype=np.float32)
#: The picture's caption: which arrow is which.
CAPTION = "simulated contact forces blue, the node's predicted green"


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


def render_grasp(hsim: HandSim, path: str | Path, predicted: list[np.ndarray] | None = None,
                 scale: float = 0.03, size: tuple[int, int] = (800, 600),
                 azimuth: float = -90.0, elevation: float = -20.0, distance: float = 0.25
                 ) -> Path:
    """
    Render the grasp and write it as PNG.

    Args:
        hsim: the simulation, in the state to draw.
        path: the PNG to write.
        predicted: certified contact forces on the object, base axes [N], one per
            planned contact, drawn beside the simulated ones.
        scale: arrow length per newton [m/N].
        size: width and height [px].

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
        camera = mujoco.MjvCamera()
        camera.lookat[:] = hsim.data.xpos[hsim.sim.object_body]
        camera.distance, camera.azimuth, camera.elevation = distance, azimuth, elevation
        renderer.update_scene(hsim.data, camera=camera)
        readings, _ = hsim.readings()
        for i, r in enumerate(readings):
            if r.touching:
                # From the contact into the (see-through) object: the push it gets.
                if predicted is not None:
                    _arrow(renderer.scene, r.position, r.position + scale * predicted[i],
                           PREDICTED_RGBA, 0.005)
                _arrow(renderer.scene, r.position, r.position + scale * r.force,
                       SIMULATED_RGBA, 0.003)
        write_png(path, renderer.render())
    finally:
        model.geom_rgba[geoms, 3] = alpha
        renderer.close()
    return Path(path)
