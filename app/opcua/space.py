"""The JogMeasure nodes in the server's address space: created on first sight of a path, written
only when a value changed (so a subscription fires on a change and stays quiet otherwise).

Node ids are the browse path in the namespace ``urn:jog-measure-hmi``: ``ns=<i>;s=Machine.MCS.X``,
``ns=<i>;s=ZeroOffsets.G54.Trans.X``; the browse names are those of design.md §9.7.
"""

from __future__ import annotations

from datetime import UTC

from asyncua import Node, Server, ua

from .values import ROOT, Path, Values, offset_target

DESCRIPTIONS = {
    ("Machine",): "Channel CHAN1 as GET /api/machine shows it",
    ("Machine", "MCS"): "Axis positions in the machine coordinate system, mm / degrees",
    ("Machine", "WCS"): "Tool tip in the active work coordinate system, mm / degrees",
    ("Machine", "ActiveOffset"): "The settable zero offset in use (G500, G54, ...)",
    ("Machine", "Alarms"): "The active alarms, JSON [{\"code\", \"text\"}] as GET /api/machine",
    ("ZeroOffsets",): "Stored zero offsets (frames); Trans/Fine/Rot are writable by a signed-in user "
                      "with the 'Write zero offsets' level",
    ("LastMeasurement",): "The newest measurement log entry as JSON, as GET /api/log",
}


async def set_if_changed(server: Server, node: Node, variant: ua.Variant, shown: dict, key) -> bool:
    """Write ``variant`` to ``node`` unless ``shown[key]`` already holds it (a subscription then
    fires only on a change)."""
    if key in shown and shown[key] == variant.Value:
        return False
    now = ua.DateTime.now(UTC)
    await server.write_attribute_value(node.nodeid, ua.DataValue(variant, SourceTimestamp=now, ServerTimestamp=now))
    shown[key] = variant.Value
    return True


class JogMeasureSpace:
    def __init__(self, server: Server, idx: int):
        self._server = server
        self._idx = idx
        self._nodes: dict[Path, Node] = {}
        self._shown: dict[Path, object] = {}
        self.writable: dict[ua.NodeId, tuple[str, str, str]] = {}    # node -> (offset, component, axis)

    def node_id(self, path: Path) -> ua.NodeId:
        return ua.NodeId(ua.String(".".join(path) if path else ROOT), ua.Int16(self._idx))

    async def build(self) -> Node:
        root = await self._server.nodes.objects.add_object(self.node_id(()), ua.QualifiedName(ROOT, self._idx))
        self._nodes[()] = root
        return root

    async def _object(self, path: Path) -> Node:
        node = self._nodes.get(path)
        if node is None:
            parent = await self._object(path[:-1])
            node = await parent.add_object(self.node_id(path), ua.QualifiedName(path[-1], self._idx))
            await self._describe(node, path)
            self._nodes[path] = node
        return node

    async def _variable(self, path: Path, value, vtype: ua.VariantType) -> Node:
        parent = await self._object(path[:-1])
        node = await parent.add_variable(self.node_id(path), ua.QualifiedName(path[-1], self._idx),
                                         ua.Variant(value, vtype))
        await self._describe(node, path)
        target = offset_target(path)
        if target is not None:
            await node.set_writable()        # who may write is decided per user (writes.py)
            self.writable[node.nodeid] = target
        self._nodes[path] = node
        return node

    async def _describe(self, node: Node, path: Path) -> None:
        text = DESCRIPTIONS.get(path)
        if text:
            await node.write_attribute(ua.AttributeIds.Description,
                                       ua.DataValue(ua.Variant(ua.LocalizedText(text), ua.VariantType.LocalizedText)))

    async def show(self, values: Values) -> int:
        """Write the changed values (creating new nodes); returns how many changed."""
        changed = 0
        for path, (value, vtype) in values.items():
            if path in self._shown and self._shown[path] == value:
                continue
            if path not in self._nodes:
                await self._variable(path, value, vtype)
            else:
                now = ua.DateTime.now(UTC)
                await self._server.write_attribute_value(
                    self.node_id(path), ua.DataValue(ua.Variant(value, vtype), SourceTimestamp=now, ServerTimestamp=now))
            self._shown[path] = value
            changed += 1
        return changed

    async def prune(self, values: Values, scopes: tuple[Path, ...]) -> int:
        """Delete the nodes below ``scopes`` that ``values`` no longer has (another scenario: other
        axes, other frames), so a client never reads a value nobody updates; returns how many."""
        kept = {path[:n] for path in values for n in range(len(path) + 1)}
        gone = [path for path in self._nodes
                if path not in kept and any(path[:len(s)] == s and len(path) > len(s) for s in scopes)]
        for path in sorted(gone, key=len):             # parents first; their subtree goes with them
            node = self._nodes.pop(path, None)
            if node is None:
                continue
            await self._server.delete_nodes([node], recursive=True)
            for below in [p for p in self._nodes if p[:len(path)] == path]:
                self.writable.pop(self._nodes.pop(below).nodeid, None)   # in place: writes.py holds it
            for below in [p for p in self._shown if p[:len(path)] == path]:
                self._shown.pop(below)
            self.writable.pop(node.nodeid, None)
        return len(gone)

    def node(self, path: Path) -> Node:
        return self._nodes[path]
