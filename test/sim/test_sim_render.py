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
from grasp_torque_opt.sim.render import CAPTION, PREDICTED_RGBA, SIMULATED_RGBA, write_png
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


def test_the_caption_names_the_arrows_colours():
    assert CAPTION == "simulated contact forces blue, the node's predicted green"
    assert hue_distance(SIMULATED_RGBA, (0, 0, 1)) < 30  # blue
    assert hue_distance(PREDICTED_RGBA, (0, 1, 0)) < 30  # green


def test_the_png_reads_back(tmp_path):
    from PIL import Image

    rgb = (np.arange(4 * 5 * 3) % 256).astype(np.uint8).reshape(4, 5, 3)
    write_png(tmp_path / 'x.png', rgb)
    with Image.open(tmp_path / 'x.png') as im:
        assert im.format == 'PNG' and np.array_equal(np.asarray(im), rgb)
