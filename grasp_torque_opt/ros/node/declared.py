# Copyright 2026 grasp_torque_opt developers
#
# Use of this source code is governed by a BSD-style
# license that can be found in the LICENSE file or at
# https://developers.google.com/open-source/licenses/bsd
#
# SPDX-License-Identifier: BSD-3-Clause


"""
The node's parameters as declared on it: declaration, the on-set check, the snapshot.

The plain node declares every parameter with its value at start (the scenario's
defaults once the scenario is loaded). The managed node declares them all at once,
those whose default comes from the scenario without a value; configure fills in the
scenario's for those still without one, and cleanup empties what it filled in. A
value given at start that rclpy refuses (out of its range, of another type) does not
end the managed node: it is kept as the reason configure fails until it is set.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from grasp_torque_opt.control.parameters.snapshot import params_from
from grasp_torque_opt.control.parameters.validators import check_pairs, Context
from grasp_torque_opt.core.exceptions import InputError
from grasp_torque_opt.ros.node.parameters import (
    descriptor,
    FIXED_WHILE_CONFIGURED,
    PARAMETERS,
    SCENARIO_PARAMETERS,
    UNSET_PARAMETERS,
)
from rcl_interfaces.msg import SetParametersResult
from rclpy.exceptions import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from rclpy.node import Node
from rclpy.parameter import Parameter


class DeclaredParameters:
    """The parameters of one node (plain or managed) and their checks on set."""

    def __init__(self, node: Node, managed: bool) -> None:
        """Belong to ``node``; nothing is declared yet."""
        self.node = node
        self.managed = managed
        self.context = Context()  # the hand's, once loaded
        self.configured = False  # read-only parameters are fixed while configured
        self.started = False  # use_sim_time is fixed once the node runs
        self.filling = False  # the managed node fills in scenario defaults
        #: Parameters whose value given at start was refused -> the reason (managed).
        self.refused: dict[str, str] = {}
        #: Parameters that configure filled in from the scenario (emptied at cleanup).
        self.filled: set[str] = set()

    def value(self, name: str) -> Any:
        """Give a parameter's value, None while it has none (declared by type only)."""
        try:
            return self.node.get_parameter(name).value
        except (ParameterUninitializedException, ParameterNotDeclaredException):
            return None  # (or, in the managed node's cleanup, being declared again)

    def values(self) -> dict[str, Any]:
        """Every parameter's value, by name (None while it has none)."""
        return {name: self.value(name) for name in PARAMETERS}

    def snapshot(self) -> Any:
        """Take a frozen, typed snapshot of every value (``p.solver.backend``)."""
        return params_from(self.values())

    def declare(self, name: str, value: Any = None) -> Any:
        """
        Declare a parameter with a value, or by type where it has none yet.

        The managed node keeps a refused value given at start as a reason.

        Returns:
            Its value.
        """
        if value is None and name in UNSET_PARAMETERS:
            return self._declare_empty(name)
        if value is None:
            value = SCENARIO_PARAMETERS[name]
        d = descriptor(name, self.managed)
        if not self.managed:
            return self.node.declare_parameter(name, value, d).value
        try:
            self.node.declare_parameter(name, value, d)
        except (InvalidParameterValueException, InvalidParameterTypeException) as e:
            why = str(e).splitlines()[0].split('Reason: ', 1)[-1]  # rclpy's words
            if why.endswith(f': {name}'):
                why = why[:-len(name) - 2]
            self.refused[name] = f'the value given at start was refused ({why})'
            self.node.declare_parameter(name, value, d, ignore_override=True)
        return self.value(name)

    def _declare_empty(self, name: str) -> Any:
        """
        Declare a parameter that may stay unset (``name_map``) with an empty list.

        rclpy types an empty list as a byte array, so it is declared by type, then set
        to an empty list of its own type: declared without a value, a get_parameters
        request that named it answered nothing at all. Its descriptor is not read-only
        (which would refuse that set); the on-set check keeps it fixed once configured.
        """
        kind = UNSET_PARAMETERS[name]
        self.node.declare_parameter(name, kind, descriptor(name, managed=True))
        if self.value(name) is None:
            self.node.set_parameters([Parameter(name, kind, [])])
        return self.value(name)

    def declare_all_managed(self) -> None:
        """Declare every parameter: the scenario's and the unset ones by type."""
        defaults = PARAMETERS.defaults()
        for name in PARAMETERS:
            self.declare(name, defaults.get(name))

    def watch(self, apply: Callable[[list[Parameter]], None]) -> None:
        """Check every change before it is taken; ``apply`` it after."""
        self.node.add_on_set_parameters_callback(self.validate)
        self.started = True
        self.node.add_post_set_parameters_callback(
            lambda params: self._applied(params, apply))

    def validate(self, params: list[Parameter]) -> SetParametersResult:
        """Refuse a change with a reason naming the parameter (on-set-parameters callback)."""
        for param in params:
            if param.name == 'use_sim_time' and self.started:
                return SetParametersResult(successful=False, reason=(
                    'use_sim_time: fixed after start (give it at start: the node judges '
                    'staleness on the steady clock either way, docs/node.md)'))
            if param.name not in PARAMETERS or param.value is None:
                continue  # not ours, or declared by type only (the managed node)
            if PARAMETERS[param.name].read_only and self.configured and not self.filling:
                return SetParametersResult(
                    successful=False, reason=f'{param.name}: {FIXED_WHILE_CONFIGURED}')
            reason = PARAMETERS.reason(param.name, param.value, self.context)
            if reason:
                return SetParametersResult(successful=False, reason=reason)
        try:
            check_pairs({**self.values(), **{p.name: p.value for p in params}}, self.context)
        except InputError as e:
            return SetParametersResult(successful=False, reason=str(e))
        return SetParametersResult(successful=True)

    def _applied(self, params: list[Parameter],
                 apply: Callable[[list[Parameter]], None]) -> None:
        if self.filling:
            return  # configure takes the values
        for param in params:  # set by the user: no longer refused, nor the scenario's
            self.refused.pop(param.name, None)
            self.filled.discard(param.name)
        apply(params)

    def first_refused(self) -> None:
        """
        Raise for a value given at start that rclpy refused (the managed node).

        Raises:
            InputError: naming it.
        """
        if self.refused:
            name, why = next(iter(self.refused.items()))
            raise InputError(name, f'{why}; set it, then configure again')

    def fill(self, defaults: dict[str, Any]) -> None:
        """
        Give the parameters still without a value the scenario's (the managed node).

        Raises:
            InputError: a value refused (it names the parameter).
        """
        self.filling = True
        try:
            for name, value in defaults.items():
                if self.value(name) is not None:
                    continue
                result = self.node.set_parameters([Parameter(name, value=value)])[0]
                if not result.successful:
                    field, _, problem = result.reason.partition(': ')
                    raise InputError(field, problem)
                self.filled.add(name)
        finally:
            self.filling = False

    def empty_filled(self) -> None:
        """Empty what :meth:`fill` filled in, so that the next configure fills it again."""
        self.filling = True
        try:
            for name in sorted(self.filled):
                self.node.undeclare_parameter(name)
                self.node.declare_parameter(name, SCENARIO_PARAMETERS[name],
                                            descriptor(name, managed=True),
                                            ignore_override=True)
        finally:
            self.filling = False
            self.filled.clear()
