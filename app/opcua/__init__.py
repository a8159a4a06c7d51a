"""OPC UA for MES, SCADA and PLCs (design.md §9.7): the HMI's machine state, zero offsets and newest
measurement on an ``opc.tcp`` endpoint in the HMI's own process, writes guarded by the access levels
(app/access), optionally with a umati MachineTool instance (``umati.py``)."""

from .endpoint import NAMESPACE, OpcUaEndpoint, OpcUaStartError, port_problem

__all__ = ["NAMESPACE", "OpcUaEndpoint", "OpcUaStartError", "port_problem"]
