"""Shared foundation of onestroke: errors, unit strings and atomic file writes.

The three domain packages (`vectorize`, `fabrication`, `machines`) may all import this
package; it imports none of them.
"""

from onestroke.errors import (
    FabricationError,
    InputError,
    MachineError,
    OnestrokeError,
    OutputError,
    VectorizeError,
)

__all__ = ["OnestrokeError", "InputError", "VectorizeError", "FabricationError", "MachineError", "OutputError"]
__version__ = "0.1.0"
