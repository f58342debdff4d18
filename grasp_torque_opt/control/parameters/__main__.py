# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""Print the parameter table of docs/node.md ("Parameters"), from the schema."""

from grasp_torque_opt.control.parameters.schema import SCHEMA

if __name__ == '__main__':
    print(SCHEMA.markdown_table(), end='')
