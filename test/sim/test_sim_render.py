# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""The picture: arrows that show against the object, a caption that names their colours."""

import colorsys

from grasp_torque_opt.sim.model import OBJECT_RGBA
from grasp_torque_opt.sim.render import CAPTION, LEGEND, PREDICTED_RGBA, SIMULATED_RGBA
from grasp_torque_opt.sim.render import write_png
import numpy as np
import pytest


def hue_distance(a, b) -> float:
    """Return the distance of two colours' hues [deg], 0 to 180."""
    ha, hb = (360 * colorsys.rgb_to_hsv(*c[:3])[0] for c in (a, b))
    return min(abs(ha - hb), 360 - abs(ha - hb))


@pytest.mark.parametrize('arrow', [SIMULATED_RGBA, PREDICTED_RGBA])
def test_the_arrows_contrast_with_the_object(arrow):
    assert hue_distance(arrow, OBJECT_RGBA) >= 90
    assert np.linalg.norm(np.asarray(arrow[:3]) - OBJECT_RGBA[:3]) >= 0.5


def luminance(c) -> float:
    """Return the relative luminance of a colour (WCAG 2), 0 to 1."""
    lin = [x / 12.92 if x <= 0.04045 else ((x + 0.055) / 1.055) ** 2.4 for x in c[:3]]
    return 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]


def test_the_caption_and_legend_name_the_arrows_colours_told_apart_at_a_glance():
    assert CAPTION.startswith("simulated contact forces blue, the node's predicted green")
    assert hue_distance(SIMULATED_RGBA, (0, 0, 1)) < 30  # blue
    assert hue_distance(PREDICTED_RGBA, (0, 1, 0)) < 30  # green
    assert SIMULATED_RGBA[3] == PREDICTED_RGBA[3] == 1.0  # opaque, neither see-through
    # WCAG's contrast ratio between the two: at least 3 (large graphics), dark vs light.
    lo, hi = sorted(luminance(c) for c in (SIMULATED_RGBA, PREDICTED_RGBA))
    assert (hi + 0.05) / (lo + 0.05) >= 3.0
    assert [text.split()[0] for _, text in LEGEND] == ['simulated', 'predicted:']


def test_the_png_reads_back(tmp_path):
    from PIL import Image

    rgb = (np.arange(4 * 5 * 3) % 256).astype(np.uint8).reshape(4, 5, 3)
    write_png(tmp_path / 'x.png', rgb)
    with Image.open(tmp_path / 'x.png') as im:
        assert im.format == 'PNG' and np.array_equal(np.asarray(im), rgb)


def test_the_allegro_picture_shows_all_four_contacts_and_its_legend(tmp_path):
    """The view is chosen so that every contact's arrows are unhidden (issue 35)."""
    from conftest import ALLEGRO
    from grasp_torque_opt.core.scenario import load_scenario
    from grasp_torque_opt.ros.sim_plan import certified_forces, simulate_candidate
    from grasp_torque_opt.sim.episode import EpisodeSettings
    from grasp_torque_opt.sim.render import choose_view, render_grasp, VIEWS
    from PIL import Image

    report, rig, controller = simulate_candidate(load_scenario(ALLEGRO),
                                                 EpisodeSettings(duration=0.3))
    readings, _ = rig.readings()
    assert report.held and all(r.touching for r in readings)
    predicted = certified_forces(controller)
    lookat = rig.data.xpos[rig.sim.object_body]
    azimuth, elevation, shown = choose_view(rig, lookat, list(enumerate(readings)),
                                            predicted, 0.03, 0.25)
    assert shown == 4 and (azimuth, elevation) != VIEWS[0]  # the old view showed two
    path = render_grasp(rig, tmp_path / 'grasp.png', predicted)
    with Image.open(path) as image:
        assert image.getpixel((20, 60)) == (255, 255, 255)  # the legend's box
        rgb = np.asarray(image.convert('RGB'), dtype=float) / 255
    # Both arrows' colours, shaded, are in the picture (below the legend's box).
    r, g, b = (rgb[100:, :, k] for k in range(3))
    assert np.count_nonzero((b > 0.4) & (b > r + 0.25) & (b > g + 0.15)) > 100  # blue
    assert np.count_nonzero((g > 0.4) & (g > r + 0.25) & (g > b + 0.2)) > 100  # green
