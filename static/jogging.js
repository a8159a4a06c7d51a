// Jogging beyond the control panel's keys (issue 17 item 7): the tab's jog feed, RAPID and rapid
// override (kept in sessionStorage and sent as X-Panel-* headers, like hmi.js does for axis and
// increment), keyboard jog with hold-to-run, and the virtual handwheel.
(function () {
  "use strict";
  var KEY = "hmi-jog";
  var RENEW_MS = 150;            // as hmi.js: the server stops a jog 0.5 s after the last renewal
  var DEG_PER_DETENT = 3.6;      // a 100-detent handwheel

  var chosen = (function () {
    try { return JSON.parse(sessionStorage.getItem(KEY)) || {}; } catch (e) { return {}; }
  })();
  function save() { try { sessionStorage.setItem(KEY, JSON.stringify(chosen)); } catch (e) { /* private mode */ } }
  function mcp() { return document.getElementById("mcp"); }
  function post(url, values) { return htmx.ajax("POST", url, { values: values || {}, swap: "none" }); }

  // --- the tab's choices: remembered before htmx sends the request (capture phase)
  document.addEventListener("change", function (event) {
    if (event.target.id === "jog-feed") chosen.feed = event.target.value;
    else if (event.target.id === "rapid-override") chosen.rov = event.target.value;
    else return;
    save();
  }, true);
  document.addEventListener("click", function (event) {
    var key = event.target.closest("#mcp #rapid");
    if (!key) return;
    chosen.rapid = key.getAttribute("aria-pressed") === "true" ? "off" : "on";
    save();
  }, true);
  document.addEventListener("htmx:configRequest", function (event) {
    var headers = event.detail.headers;
    if (chosen.feed !== undefined) headers["X-Panel-Feed"] = chosen.feed;
    if (chosen.rapid) headers["X-Panel-Rapid"] = chosen.rapid;
    if (chosen.rov) headers["X-Panel-Rov"] = chosen.rov;
  });
  function differs(panel, withKeys) {      // the panel shows other choices than the tab holds
    var keys = {};                          // hmi.js's: axis and increment
    if (withKeys) try { keys = JSON.parse(sessionStorage.getItem("hmi-panel")) || {}; } catch (e) { /* private mode */ }
    return (keys.axis && keys.axis !== panel.dataset.axis) || (keys.increment && keys.increment !== panel.dataset.increment) ||
           (chosen.feed !== undefined && chosen.feed !== panel.dataset.jogFeed) ||
           (chosen.rapid && chosen.rapid !== panel.dataset.rapid) || (chosen.rov && chosen.rov !== panel.dataset.rov);
  }
  function redraw(panel) { htmx.ajax("POST", panel.dataset.jogFeedUrl, { target: "#mcp", swap: "outerHTML", values: {} }); }
  document.addEventListener("DOMContentLoaded", function () {     // a page load renders the defaults
    var panel = mcp();
    if (panel && differs(panel, false)) redraw(panel);         // axis and increment: hmi.js restorePanel
  });
  // Panel answers can overtake each other or land on a panel already replaced (a key pressed
  // while the previous answer was on its way): once none is on its way, the panel must show what
  // the tab holds, else it is drawn once more (the choices travel as headers, so that answer is right).
  // loadend of the request itself: htmx's own events do not reach the page from a replaced panel.
  var panelRequests = 0, redraws = 0;
  document.addEventListener("htmx:beforeRequest", function (event) {
    var target = event.detail.target;
    if (!target || target.id !== "mcp") return;
    panelRequests++;
    event.detail.xhr.addEventListener("loadend", function () {
      panelRequests--;
      setTimeout(function () {
        var panel = mcp();
        if (!panel || panelRequests > 0) return;
        if (!differs(panel, true)) { redraws = 0; return; }
        if (redraws < 3) { redraws++; redraw(panel); }           // never a loop on a refused value
      }, 0);
    });
  });

  // --- keyboard jog, hold-to-run: the arrow keys move X and Y, Page Up/Down Z, Shift = rapid.
  // The jog runs while the key is down; key up, leaving the window or hiding the tab stop it.
  var KEYS = { ArrowRight: ["X", "+"], ArrowLeft: ["X", "-"], ArrowUp: ["Y", "+"], ArrowDown: ["Y", "-"],
               PageUp: ["Z", "+"], PageDown: ["Z", "-"] };
  var held = null;      // {code, timer, stop}
  function typing(target) {
    return target && (target.isContentEditable || /^(INPUT|SELECT|TEXTAREA)$/.test(target.tagName) ||
                      target.id === "handwheel");
  }
  function stopKeyJog() {
    if (!held) return;
    clearInterval(held.timer);
    var stop = held.stop;
    held = null;
    post(stop);
  }
  document.addEventListener("keydown", function (event) {
    var move = KEYS[event.key];
    var panel = mcp();
    if (!move || !panel || event.ctrlKey || event.altKey || event.metaKey || typing(event.target)) return;
    if (!panel.querySelector('[data-axis="' + move[0] + '"]')) return;     // the machine has no such axis
    event.preventDefault();
    if (held) return;                                                      // key repeat: already running
    var values = { axis: move[0], direction: move[1] };
    if (event.shiftKey) values.rapid = "on";                               // else the panel's RAPID key
    var start = panel.dataset.jogStart;
    post(start, values);
    held = { code: event.key, stop: panel.dataset.jogStop,
             timer: setInterval(function () { post(start, values); }, RENEW_MS) };
  });
  document.addEventListener("keyup", function (event) { if (held && event.key === held.code) stopKeyJog(); });
  window.addEventListener("blur", stopKeyJog);
  document.addEventListener("visibilitychange", function () { if (document.hidden) stopKeyJog(); });
  window.addEventListener("pagehide", stopKeyJog);

  // --- the virtual handwheel: each detent moves the tab's axis by its increment. Detents turned
  // while a move runs are added up and sent together, so none is lost and none is sent twice.
  var pending = 0;
  var sending = false;
  var angle = 0;
  function turn(detents) {
    var wheel = document.getElementById("handwheel");
    if (!wheel || !detents) return;
    angle += detents * DEG_PER_DETENT;
    var mark = wheel.querySelector(".handwheel-mark");
    if (mark) mark.style.transform = "rotate(" + angle + "deg)";
    wheel.setAttribute("aria-valuenow", String(Math.round(angle / DEG_PER_DETENT)));
    pending += detents;
    flush();
  }
  function flush() {
    var panel = mcp();
    if (sending || !pending || !panel) return;
    var detents = pending;
    pending = 0;
    sending = true;
    var done = function () { sending = false; flush(); };
    post(panel.dataset.handwheelUrl, { detents: detents, axis: panel.dataset.axis }).then(done, done);
  }
  document.addEventListener("wheel", function (event) {
    if (!event.target.closest("#handwheel")) return;
    event.preventDefault();
    turn(event.deltaY < 0 ? 1 : -1);             // one notch of the mouse wheel = one detent
  }, { passive: false });
  document.addEventListener("keydown", function (event) {
    if (event.target.id !== "handwheel") return;
    var step = { ArrowUp: 1, ArrowRight: 1, ArrowDown: -1, ArrowLeft: -1 }[event.key];
    if (!step) return;
    event.preventDefault();
    turn(step);
  });
  var drag = null;     // {cx, cy, last} angle in degrees about the wheel's centre
  function pointerAngle(event) { return Math.atan2(event.clientY - drag.cy, event.clientX - drag.cx) * 180 / Math.PI; }
  document.addEventListener("pointerdown", function (event) {
    var wheel = event.target.closest("#handwheel");
    if (!wheel) return;
    event.preventDefault();
    var box = wheel.getBoundingClientRect();
    drag = { cx: box.left + box.width / 2, cy: box.top + box.height / 2, rest: 0 };
    drag.last = pointerAngle(event);
    if (wheel.setPointerCapture) wheel.setPointerCapture(event.pointerId);
  });
  document.addEventListener("pointermove", function (event) {
    if (!drag) return;
    var now = pointerAngle(event);
    var delta = ((now - drag.last + 540) % 360) - 180;           // the short way round
    drag.last = now;
    drag.rest += delta;
    var detents = drag.rest > 0 ? Math.floor(drag.rest / DEG_PER_DETENT) : Math.ceil(drag.rest / DEG_PER_DETENT);
    drag.rest -= detents * DEG_PER_DETENT;
    turn(detents);                                               // clockwise = plus
  });
  ["pointerup", "pointercancel"].forEach(function (name) {
    document.addEventListener(name, function () { drag = null; });
  });
})();
