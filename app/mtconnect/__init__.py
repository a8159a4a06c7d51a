"""MTConnect for shops that run an MTConnect agent (docs/opcua.md "MTConnect"): a read-only SHDR
adapter in the HMI's process on ``--mtconnect PORT``."""

from .adapter import MtConnectStartError, ShdrAdapter, port_problem

__all__ = ["MtConnectStartError", "ShdrAdapter", "port_problem"]
