"""pyserial URL handlers of onestroke: `sim://` opens a GRBL emulator on a pseudo-terminal.

Registered by `machines.ports.open_port` (it appends this package to
`serial.protocol_handler_packages`), so `serial.serial_for_url("sim://")` works.
"""
