"""`onestroke ports`: list serial ports and find the GRBL machines among them."""

from __future__ import annotations

import dataclasses

import click

from fabrication.cli.common import console, done
from fabrication.cli.options import BaudRate
from machines.ports import list_ports, probe_grbl
from onestroke.errors import MachineError


@click.command("ports")
@click.option("--probe/--no-probe", default=True, show_default=True,
              help="Open USB serial ports and wait for GRBL's welcome (resets the board).")
@click.option("--all", "probe_all", is_flag=True, help="Probe built-in serial ports too, not only USB ones.")
@click.option("--baud", type=BaudRate(), default=115200, show_default=True, help="Baud rate for probing.")
def ports(probe: bool, probe_all: bool, baud: int) -> None:
    """List serial ports with their descriptions; mark the ones answering as GRBL."""
    found = list_ports(probe=False)
    if probe:
        console.print("probing serial ports for GRBL (up to 2.5 s each) ...")
        probed = []
        for port in found:
            if port.vid is None and not probe_all:
                probed.append(port)  # built-in UARTs: probing them only costs time
                continue
            try:
                probed.append(dataclasses.replace(port, grbl_version=probe_grbl(port.device, baud=baud)))
            except MachineError as error:
                probed.append(dataclasses.replace(port, problem=str(error)))
        found = probed
    if not found:
        done("no serial ports found: plug the machine in over USB (and switch it on); on Linux check 'dmesg'")
        return
    grbl = 0
    for port in found:
        if port.grbl_version:
            grbl += 1
            verdict = f"GRBL {port.grbl_version}"
        elif port.problem:
            verdict = port.problem
        else:
            verdict = "no GRBL answer" if probe and (port.vid is not None or probe_all) else "-"
        ids = f" [{port.vid:04x}:{port.pid:04x}]" if port.vid is not None and port.pid is not None else ""
        click.echo(f"{port.device}\t{port.description}{ids}\t{verdict}")
    done(f"{len(found)} serial port(s), {grbl} GRBL" + ("" if probe else " (not probed)"))
