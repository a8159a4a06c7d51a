// The live feed (GET /api/events, design.md §9.9) in place of polling: the position values are
// written straight from each "machine" event; the header, the position block, the alarm pane and
// anything listening for "hmi-state" (machine) or "hmi-session" (measuring session) are refreshed
// by htmx when that state changes. A feed quiet for WATCHDOG_MS shows the connection as lost
// (the server sends the state at least 4 times a second).
(function () {
  "use strict";
  var WATCHDOG_MS = 1000;
  var url = document.body && document.body.dataset.events;
  if (!url || !window.EventSource) return;

  var lastSeen = Date.now();
  var machineSig = null;
  var sessionSig = null;
  var lastSession = null;       // the newest session event's signature (sessionSig: the one last asked for)
  var quiet = false;

  function connection(ok) {
    if (quiet === !ok) return;
    quiet = !ok;
    document.dispatchEvent(new CustomEvent("hmi:connection", { detail: { ok: ok } }));
  }
  function seen() { lastSeen = Date.now(); connection(true); }
  setInterval(function () { if (Date.now() - lastSeen > WATCHDOG_MS) connection(false); }, 200);

  function fixed(value, decimals) {         // as app/web/templating.py fixed(): no "-0.000"
    var text = value.toFixed(decimals);
    return parseFloat(text) === 0 ? (0).toFixed(decimals) : text;
  }
  function showPositions(state) {
    var box = document.getElementById("position-values");
    if (!box) return;
    var values = box.dataset.coords === "MCS" ? state.mcs : state.wcs;
    box.querySelectorAll("td.value[data-axis]").forEach(function (cell) {
      var value = values && values[cell.dataset.axis];
      if (typeof value !== "number") return;
      cell.textContent = fixed(value / parseFloat(cell.dataset.scale || "1"), parseInt(cell.dataset.decimals || "3", 10));
    });
  }
  // what the header, the position block's T/F/SP/State table and the alarm pane show
  function machineSignature(s) {
    return JSON.stringify([s.mode, s.active_offset, s.plane, s.tool, s.tool_length, s.feed_override,
                           s.spindle_angle, s.busy, s.program_state, s.alarms]);
  }
  function sessionSignature(s) {
    return JSON.stringify([s.id, s.running, s.progress, s.alarm, s.points, s.notice, s.answer && s.answer.log_id]);
  }
  function changed(previous, now, name) {      // the first event (after loading, after a reconnect) too:
    if (previous !== now) htmx.trigger(document.body, name);     // what changed since the page was made
    return now;
  }

  // an answer the browser gave up on (htmx's timeout, a send error) drew nothing: the next event
  // asks again, since a state that no longer changes would never ask (e.g. a measurement's outcome)
  ["htmx:timeout", "htmx:sendError"].forEach(function (name) {
    document.addEventListener(name, function () { machineSig = sessionSig = null; });
  });

  // the tab's id (static/hmi.js): the server stops this tab's held jog when the feed drops
  var tab = window.hmiTabId ? window.hmiTabId() : "";
  var source = new EventSource(tab ? url + (url.indexOf("?") < 0 ? "?" : "&") + "tab=" + encodeURIComponent(tab) : url);
  source.addEventListener("open", function () { seen(); });
  source.addEventListener("machine", function (event) {
    seen();
    var state = JSON.parse(event.data);
    showPositions(state);
    var sig = machineSignature(state);
    machineSig = changed(machineSig, sig, "hmi-state");
    if (sessionSig === null && lastSession !== null) sessionSig = changed(null, lastSession, "hmi-session");
  });
  source.addEventListener("session", function (event) {
    seen();
    lastSession = sessionSignature(JSON.parse(event.data));
    sessionSig = changed(sessionSig, lastSession, "hmi-session");
  });
  source.addEventListener("error", function () { machineSig = sessionSig = lastSession = null; });
  window.addEventListener("pagehide", function () { source.close(); });
})();
