// The live feed (GET /api/events, design.md §9.9) in place of polling: the position values are
// written straight from each "machine" event; the header, the position block, the alarm pane and
// anything listening for "hmi-state" (machine) or "hmi-session" (measuring session) are refreshed
// by htmx when that state changes; the position title follows the active WO at once, and a change
// of the screens' units (the settings, by any tab or the API) draws the screen again. A feed quiet
// for WATCHDOG_MS, or a broken link, shows the connection as lost (the server sends the state at
// least 4 times a second; a late answer alone is "busy", static/hmi.js).
(function () {
  "use strict";
  var WATCHDOG_MS = 3000;
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
  function showOffset(state) {
    document.querySelectorAll("#position .pos-wo").forEach(function (wo) {
      if (state.active_offset && wo.textContent !== state.active_offset) wo.textContent = state.active_offset;
    });
  }
  // the units of the page (body data-units) differ from the settings': every number of the screen is
  // in the old unit, so the screen is drawn again (the position block follows "hmi-state")
  var unitsAsked = null;
  function followUnits(state) {
    var body = document.body;
    if (!state.units || body.dataset.units === state.units || unitsAsked === state.units) return;
    unitsAsked = state.units;
    var screen = document.getElementById("screen");
    var done = function () { body.dataset.units = state.units; unitsAsked = null; };
    if (!screen) { done(); return; }
    htmx.ajax("GET", window.location.pathname + window.location.search, { target: "#screen", swap: "outerHTML" })
      .then(done, function () { unitsAsked = null; });
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
  // the probes' lamps and the running probe test (design.md §10.4), painted at once from the event
  // (the screen shows "switched" within milliseconds; the blocks are fetched again after it)
  function lampState(p, which) {
    if (!p) return "none";
    if (p.deflected) return "deflected";
    if (p.deflected === null) return "unknown";
    if (which === "workpiece" && !p.in_spindle) return "absent";
    if (p.armed === false) return "off";
    return "ready";
  }
  function showText(box, name, state) {
    var text = box.querySelector(name);
    var key = "text" + state.split(/[-_]/).map(function (w) { return w.charAt(0).toUpperCase() + w.slice(1); }).join("");
    if (text && box.dataset[key]) text.textContent = box.dataset[key];
  }
  function showProbes(state) {
    document.querySelectorAll("[data-probe-lamp]").forEach(function (lamp) {
      var which = lamp.dataset.probeLamp;
      var now = lampState(which === "tool" ? state.tool_probe : state.probe, which);
      if (lamp.dataset.state === now) return;
      lamp.classList.remove("lamp-" + lamp.dataset.state);
      lamp.classList.add("lamp-" + now);
      lamp.dataset.state = now;
      showText(lamp, ".lamp-text", now);
    });
    var test = document.getElementById("probe-test");
    if (!test) return;
    var probe = test.dataset.probe === "tool" ? state.tool_probe : state.probe;
    var next = null;
    if (test.dataset.state === "waiting" && probe && probe.deflected) next = "switched";
    else if (test.dataset.state === "switched" && probe && probe.deflected === false) next = "passed";
    if (!next) return;
    test.classList.remove("test-" + test.dataset.state);
    test.classList.add("test-" + next);
    test.dataset.state = next;
    showText(test, ".test-text", next);
  }
  // what the header, the position block's T/F/SP/State table, the alarm pane and the probe pane show
  function machineSignature(s) {
    return JSON.stringify([s.mode, s.active_offset, s.plane, s.units, s.tool, s.tool_length, s.feed_override,
                           s.spindle_angle, s.busy, s.program_state, s.alarms, s.probe, s.tool_probe]);
  }
  function sessionSignature(s) {
    return JSON.stringify([s.id, s.running, s.progress, s.alarm, s.points, s.notice, s.answer && s.answer.log_id]);
  }
  var stateAsks = 0;                            // how often "hmi-state" asked the screen again
  function changed(previous, now, name) {      // the first event (after loading, after a reconnect) too:
    if (previous !== now) {                    // what changed since the page was made
      if (name === "hmi-state") stateAsks++;
      htmx.trigger(document.body, name);
    }
    return now;
  }
  // a newer state that asks while an element's refresh is still under way is queued by htmx on that
  // element, and dropped with it when the older answer replaces it (outerHTML): the header kept an
  // old offset. Such an answer asks again, for the state that came meanwhile.
  document.body.addEventListener("htmx:beforeRequest", function (event) {
    event.detail.elt.hmiStateAsks = stateAsks;
  });
  document.body.addEventListener("htmx:beforeSwap", function (event) {   // (the replaced one hears nothing after)
    var elt = event.detail.elt || event.target;
    if (elt.hmiStateAsks !== undefined && elt.hmiStateAsks < stateAsks)
      setTimeout(function () { htmx.trigger(document.body, "hmi-state"); }, 0);     // once it is swapped
  });

  // an answer the browser gave up on (htmx's timeout, a send error) drew nothing: the next event
  // asks again, since a state that no longer changes would never ask (e.g. a measurement's outcome)
  ["htmx:timeout", "htmx:sendError"].forEach(function (name) {
    document.addEventListener(name, function () { machineSig = sessionSig = null; });
  });

  // the mode group (issue 24 §4): what runs (status.lock) greys out what it locks, and says why
  function showLock(state) {
    var lock = state.lock || null;
    var program = lock && lock.mode !== "JOG" ? lock : null;
    var mcp = document.getElementById("mcp");
    if (mcp) {
      mcp.classList.toggle("locked", !!program);
      mcp.querySelectorAll(".key.jog").forEach(function (key) { key.disabled = !!program; });
      var note = document.getElementById("mcp-lock");
      if (note) {
        note.hidden = !program;
        note.querySelector(".lock-program").textContent = program ? program.mode + " " + program.program : "";
      }
    }
    var start = document.getElementById("mda-start");
    if (start) start.disabled = !!(lock && lock.mode === "JOG");
    var jogNote = document.getElementById("mda-lock");
    if (jogNote) {
      jogNote.hidden = !(lock && lock.mode === "JOG");
      jogNote.querySelector(".lock-program").textContent = lock && lock.mode === "JOG" ? lock.program : "";
    }
  }

  // the feed opens once htmx has read the page (its DOMContentLoaded listener, registered in <head>,
  // runs before this one): an event that came earlier asked elements nobody listened on yet, and a
  // state that no longer changes would never ask again (the header stayed as the page was made).
  // A deferred script runs before DOMContentLoaded, with the document "interactive" already.
  if (document.readyState === "complete") listen();
  else document.addEventListener("DOMContentLoaded", listen);

  function listen() {
    // the tab's id (static/hmi.js): the server stops this tab's held jog when the feed drops
    var tab = window.hmiTabId ? window.hmiTabId() : "";
    var source = new EventSource(tab ? url + (url.indexOf("?") < 0 ? "?" : "&") + "tab=" + encodeURIComponent(tab) : url);
    source.addEventListener("open", function () { seen(); });
    source.addEventListener("machine", function (event) {
      seen();
      var state = JSON.parse(event.data);
      showPositions(state);
      showOffset(state);
      followUnits(state);
      showLock(state);
      showProbes(state);
      var sig = machineSignature(state);
      machineSig = changed(machineSig, sig, "hmi-state");
      if (sessionSig === null && lastSession !== null) sessionSig = changed(null, lastSession, "hmi-session");
    });
    source.addEventListener("session", function (event) {
      seen();
      lastSession = sessionSignature(JSON.parse(event.data));
      sessionSig = changed(sessionSig, lastSession, "hmi-session");
    });
    source.addEventListener("error", function () {          // the link broke (the browser reconnects)
      machineSig = sessionSig = lastSession = null;
      if (source.readyState !== EventSource.OPEN) connection(false);
    });
    window.addEventListener("pagehide", function () { source.close(); });
  }
})();
