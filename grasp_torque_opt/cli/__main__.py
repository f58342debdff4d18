# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""``python -m grasp_torque_opt.cli``: the command line, as ``grasp-torque-opt``."""

import sys

from grasp_torque_opt.cli import main

if __name__ == '__main__':
    sys.exit(main())
