// Only what htmx cannot do: keyboard shortcuts, NC Start dispatch, the tab's own control panel,
// hold-to-run jogging and the connection state. URLs come from the page (data-url of #nc-start,
// data-jog-start/-stop of #mcp), made from route names.
(function () {
  "use strict";

  // --- the control panel of this tab (axis, increment, WCS/MCS): kept in sessionStorage and
  // sent with every request, so two tabs never share a selection (design.md §9.1)
  var PANEL_KEY = "hmi-panel";
  var panel = (function () {
    try { return JSON.parse(sessionStorage.getItem(PANEL_KEY)) || {}; } catch (e) { return {}; }
  })();
  function savePanel() {
    try { sessionStorage.setItem(PANEL_KEY, JSON.stringify(panel)); } catch (e) { /* private mode */ }
  }
  // a panel key pressed while the panel's previous answer is on its way is pressed again on the
  // new panel (the old one, and a request from it, are gone with the swap: the key would be lost)
  var panelBusy = false, pendingKey = null;
  document.addEventListener("click", function (event) {     // capture: before htmx sends the request
    var key = event.target.closest("#mcp [data-axis], #mcp [data-increment], #position [data-coords]");
    if (!key) return;
    if (panelBusy && key.closest("#mcp")) {
      event.preventDefault();
      event.stopImmediatePropagation();
      pendingKey = key.dataset.axis ? '[data-axis="' + key.dataset.axis + '"]'
                                    : '[data-increment="' + key.dataset.increment + '"]';
      return;
    }
    if (key.dataset.axis) panel.axis = key.dataset.axis;
    if (key.dataset.increment) panel.increment = key.dataset.increment;
    if (key.dataset.coords) panel.coords = key.dataset.coords;
    savePanel();
  }, true);
  function isPanelKey(elt) {
    return !!(elt && elt.closest && elt.closest("#mcp") && (elt.dataset.axis || elt.dataset.increment));
  }
  var panelSince = 0;
  document.addEventListener("htmx:beforeRequest", function (event) {
    if (!isPanelKey(event.detail.elt)) return;
    event.detail.xhr.hmiPanel = true;        // the old key may be gone when the answer comes
    panelBusy = true;
    panelSince = Date.now();
  });
  setInterval(function () {                  // never hold the panel's keys for longer than 2 s
    if (panelBusy && Date.now() - panelSince > 2000) { panelBusy = false; pendingKey = null; }
  }, 500);
  document.addEventListener("htmx:afterRequest", function (event) {
    if (!(event.detail.xhr && event.detail.xhr.hmiPanel)) return;
    setTimeout(function () {                                 // after the swap has settled
      panelBusy = false;
      var next = pendingKey && document.querySelector("#mcp button" + pendingKey);
      pendingKey = null;
      if (next) next.click();
    }, 30);
  });
  document.addEventListener("htmx:configRequest", function (event) {
    var headers = event.detail.headers;
    if (panel.axis) headers["X-Panel-Axis"] = panel.axis;
    if (panel.increment) headers["X-Panel-Increment"] = panel.increment;
    if (panel.coords) headers["X-Panel-Coords"] = panel.coords;
    var mode = document.getElementById("hdr-mode");        // the mode this tab's screen selects
    if (mode && mode.dataset.selected) headers["X-Panel-Mode"] = mode.dataset.selected;
  });
  function restorePanel() {     // a page load renders the defaults: show this tab's selection
    var mcp = document.getElementById("mcp");
    var position = document.getElementById("position-values");
    if (mcp && ((panel.axis && mcp.dataset.axis !== panel.axis) ||
                (panel.increment && mcp.dataset.increment !== panel.increment))) {
      htmx.ajax("POST", mcp.dataset.panelUrl, { target: "#mcp", swap: "outerHTML",
                                                values: { increment: panel.increment || mcp.dataset.increment } });
    }
    if (position && panel.coords && position.dataset.coords !== panel.coords) {
      htmx.ajax("POST", position.dataset.coordsUrl, { target: "#position", swap: "outerHTML",
                                                      values: { coords: panel.coords } });
    }
  }
  document.addEventListener("DOMContentLoaded", restorePanel);

  // --- connection: "lost" when the live feed (static/live.js) has been quiet for 3 s or its link
  // broke, or a request could not be sent; "busy" when answers come late (an htmx timeout, or a
  // request on its way for over BUSY_MS) while the feed still runs. Both lie over the header (CSS):
  // the layout never moves. The next answer or event clears them.
  var BUSY_MS = 1500;
  var lost = false, busy = false, pending = 0, pendingSince = 0;
  function show() {
    document.body.classList.toggle("offline", lost);
    var banner = document.getElementById("connection");
    if (banner) banner.hidden = !lost;
    var late = document.getElementById("busy");
    if (late) late.hidden = lost || !busy;
  }
  function connection(ok) {
    if (ok === !lost) return;
    lost = !ok;
    if (ok) busy = false;
    show();
  }
  function slow(yes) {
    if (busy === yes) return;
    busy = yes;
    show();
  }
  window.hmiConnection = connection;         // the hold-to-run renewals report a failed send
  document.addEventListener("htmx:sendError", function () { connection(false); });
  document.addEventListener("htmx:timeout", function () { slow(true); });
  document.addEventListener("htmx:beforeRequest", function () {
    if (pending++ === 0) pendingSince = Date.now();
  });
  document.addEventListener("htmx:afterRequest", function (event) {
    pending = Math.max(0, pending - 1);
    var xhr = event.detail.xhr;
    if (xhr && xhr.status > 0 && xhr.status < 500) { connection(true); slow(false); }
    else if (xhr && xhr.status >= 500) connection(false);
  });
  setInterval(function () { if (pending > 0 && Date.now() - pendingSince > BUSY_MS) slow(true); }, 250);
  // the live feed (static/live.js) says when its events stop and come back
  document.addEventListener("hmi:connection", function (event) { connection(event.detail.ok); });
  document.addEventListener("htmx:responseError", function (event) {    // 4xx/5xx: say why
    var message = document.getElementById("message");
    var xhr = event.detail.xhr;
    if (!message || !xhr) return;
    try {
      var body = JSON.parse(xhr.responseText);
      if (body && body.error) {
        message.textContent = body.error.message;
        message.className = "message error";
      }
    } catch (e) { /* an HTML answer swaps itself */ }
  });

  // --- answers for the screen (#screen) are drawn in the order they were asked for. Two on their
  // way at once were both aimed at the screen as it was: the second to arrive would be drawn into
  // the screen the first replaced, i.e. nowhere (NC Start right after a new target: the outcome
  // was lost). So it goes to the screen shown now, unless a later-asked answer was drawn already.
  // htmx tells of a swap on its target, which may be out of the page by then: the guard listens there
  var screenAsked = 0, screenDrawn = 0;
  function drawInOrder(event) {
    var ask = event.detail.xhr && event.detail.xhr.hmiScreenAsk;
    if (!ask || !event.detail.shouldSwap) return;
    if (ask < screenDrawn) { event.detail.shouldSwap = false; return; }     // outdated
    screenDrawn = ask;
    var shown = document.getElementById("screen");
    if (shown && !document.body.contains(event.detail.target)) event.detail.target = shown;
  }
  document.addEventListener("htmx:beforeRequest", function (event) {
    var target = event.detail.target;
    if (!target || target.id !== "screen") return;
    event.detail.xhr.hmiScreenAsk = ++screenAsked;
    if (!target.hmiDrawsInOrder) {
      target.hmiDrawsInOrder = true;
      target.addEventListener("htmx:beforeSwap", drawInOrder);
    }
  });

  // --- a new correction target re-renders the measuring screen, and a set-up support answer its
  // screen, with the form as it was sent: what the operator typed or chose while that answer was
  // on its way is put back (nothing typed is lost); on set-up support it is then sent again, since
  // the screen's texts follow the answers
  var RESENT_FORMS = { "setup-form": true };
  function formValues(form) {
    var values = {};
    new FormData(form).forEach(function (value, name) { values[name] = String(value); });
    return values;
  }
  function refreshingForm(event) {
    var elt = event.detail.elt;
    if (!elt || !elt.form) return null;
    var id = elt.form.id;
    return (id === "task-form" && elt.name === "target") || (RESENT_FORMS[id] && elt.name) ? elt.form : null;
  }
  document.addEventListener("htmx:beforeRequest", function (event) {
    var form = refreshingForm(event);
    if (form) event.detail.xhr.hmiSent = { form: form.id, by: event.detail.elt.name, values: formValues(form) };
  });
  document.addEventListener("htmx:beforeSwap", function (event) {
    var sent = event.detail.xhr && event.detail.xhr.hmiSent;
    var form = sent && document.getElementById(sent.form);
    if (!form) return;
    var now = formValues(form), changed = {};
    Object.keys(now).forEach(function (name) {
      if (name !== sent.by && now[name] !== sent.values[name]) changed[name] = now[name];
    });
    if (Object.keys(changed).length) event.detail.xhr.hmiChanged = { form: sent.form, values: changed };
  });
  // put back as soon as the answer is in (htmx:afterSwap), not after htmx's settle delay: an NC
  // Start pressed in between sent the answer's values, not the typed ones (seen once under load);
  // a resent form is sent again once settled, when htmx has taken in the new controls
  function putBack(event) {
    var xhr = event.detail.xhr;
    var changed = xhr && xhr.hmiChanged;
    var form = changed && document.getElementById(changed.form);
    if (!form) return;
    delete xhr.hmiChanged;
    var first = null;
    Object.keys(changed.values).forEach(function (name) {
      var value = changed.values[name];
      form.querySelectorAll('[name="' + CSS.escape(name) + '"]').forEach(function (control) {
        if (control.closest(".field.locked") || control.disabled && control.type !== "radio") return;
        if (control.tagName === "SELECT" && !control.querySelector('option[value="' + CSS.escape(value) + '"]')) return;
        if (control.type === "radio") {
          control.checked = control.value === value;
          var choice = control.closest(".pos-choice");
          if (choice) choice.classList.toggle("on", control.checked);
        } else {
          control.value = value;
        }
        first = first || control;
      });
    });
    if (first && RESENT_FORMS[changed.form]) xhr.hmiResend = first;
  }
  document.addEventListener("htmx:afterSwap", putBack);
  document.addEventListener("htmx:afterSettle", function (event) {
    putBack(event);
    var xhr = event.detail.xhr, first = xhr && xhr.hmiResend;
    if (!first) return;
    delete xhr.hmiResend;
    if (document.body.contains(first)) htmx.trigger(first, "change");
  });

  function post(url, data) {
    // htmx.ajax swaps the answer (the message block) out of band, like a normal htmx request
    return htmx.ajax("POST", url, { values: data || {}, swap: "none" });
  }

  // --- keyboard: F1..F8 horizontal, Shift+F1..F8 vertical, Ctrl+Enter NC Start, Escape Reset
  document.addEventListener("keydown", function (event) {
    var match = /^F([1-8])$/.exec(event.key);
    if (match) {
      var selector = event.shiftKey ? '#vsoftkeys [data-key="S-F' + match[1] + '"]'
                                    : '#hsoftkeys [data-key="F' + match[1] + '"]';
      var key = document.querySelector(selector);
      event.preventDefault();
      if (key) key.click();
      return;
    }
    if (event.key === "Enter" && event.ctrlKey) {
      event.preventDefault();
      document.getElementById("nc-start").click();
    } else if (event.key === "Escape") {
      event.preventDefault();
      document.getElementById("reset").click();
    }
  });

  // --- a level that may not run this screen's task (data-start-denied on #screen, issue 29
  // item 4): NC Start is disabled with the reason from the moment the screen opens, not refused
  // after the press; the next screen that allows it enables it again
  function showStartLock() {
    var key = document.getElementById("nc-start");
    if (!key) return;
    var screen = document.getElementById("screen");
    var reason = screen ? screen.getAttribute("data-start-denied") : null;
    if (reason) {
      key.disabled = true;
      key.title = reason;
      key.classList.add("denied");
      key.dataset.levelLock = "1";
    } else if (key.dataset.levelLock) {
      key.disabled = false;
      key.removeAttribute("title");
      key.classList.remove("denied");
      delete key.dataset.levelLock;
    }
  }
  document.addEventListener("DOMContentLoaded", showStartLock);
  document.addEventListener("htmx:afterSettle", showStartLock);
  document.addEventListener("htmx:historyRestore", showStartLock);

  // --- NC Start: a measuring screen marks its start element with data-ncstart and
  // hx-trigger="ncstart"; without one NC Start has no function here (JOG basic screen).
  document.addEventListener("click", function (event) {
    var key = event.target.closest("#nc-start");
    if (!key) return;
    var target = document.querySelector("#screen [data-ncstart]");
    if (target) htmx.trigger(target, "ncstart");
    else post(key.dataset.url);
  });

  // --- NC Start's answer given up on (htmx's timeout, a loaded computer): the measurement runs on
  // in the HMI, but the screen stayed as before NC Start and nothing on it follows the session, so
  // it asks for the screen with the progress or the outcome (data-progress), again while that
  // answer too is given up on
  document.addEventListener("htmx:timeout", function (event) {
    var form = document.querySelector("#screen [data-progress]");
    if (!form) return;
    var detail = event.detail || {};
    var path = detail.requestConfig && detail.requestConfig.path ? detail.requestConfig.path.split("?")[0] : "";
    if (detail.elt === form || path === form.dataset.progress.split("?")[0])
      htmx.ajax("GET", form.dataset.progress, { target: "#screen", swap: "outerHTML" });
  });

  // --- continuous jog: press and hold (only when the MCP is in "Cont" mode). Hold-to-run: the
  // jog is renewed every RENEW_MS while the key is held; the server stops the axis 0.5 s after
  // the last renewal, so a lost tab, network or server stops it too (design.md §9.1). Each key
  // press has a number and the tab an id (issue 24 §6): the release names the press, so a
  // renewal still on its way behind the release is ignored; the release goes out at once (fetch,
  // not behind queued htmx requests); the server also stops the jog when this tab's live feed
  // (static/live.js, same tab id) drops.
  var RENEW_MS = 150;
  var holding = null;     // {key, stop, timer, press}
  var presses = 0;
  function tabId() {
    var body = document.body;
    if (!body.dataset.tab) body.dataset.tab = Math.random().toString(36).slice(2) + Date.now().toString(36);
    return body.dataset.tab;
  }
  window.hmiTabId = tabId;
  function csrfHeaders() {
    try { return JSON.parse(document.body.getAttribute("hx-headers") || "{}"); } catch (e) { return {}; }
  }
  function send(url, values) {       // straight out, keepalive: also while the page goes away
    var headers = csrfHeaders();
    headers["Content-Type"] = "application/x-www-form-urlencoded";
    return fetch(url, { method: "POST", body: new URLSearchParams(values).toString(), headers: headers,
                        credentials: "same-origin", keepalive: true })
      .catch(function () { connection(false); });
  }
  function release() {
    if (!holding) return;
    holding.key.classList.remove("pressed");
    clearInterval(holding.timer);
    var stop = holding.stop, press = holding.press;
    holding = null;
    send(stop, { tab: tabId(), press: String(press) });
  }
  document.addEventListener("pointerdown", function (event) {
    var key = event.target.closest("#mcp[data-increment='cont'] [data-jog]");
    if (!key) return;
    event.preventDefault();
    if (holding) release();
    var mcp = key.closest("#mcp");
    presses += 1;
    var values = { direction: key.dataset.jog, axis: mcp.dataset.axis, tab: tabId(), press: String(presses) };
    key.classList.add("pressed");
    if (key.setPointerCapture) key.setPointerCapture(event.pointerId);
    post(mcp.dataset.jogStart, values);           // the first one through htmx: its message shows
    var url = mcp.dataset.jogStart;
    holding = { key: key, stop: mcp.dataset.jogStop, press: presses,
                timer: setInterval(function () { send(url, values); }, RENEW_MS) };
  });
  ["pointerup", "pointercancel", "lostpointercapture"].forEach(function (name) {
    document.addEventListener(name, release);
  });
  window.addEventListener("blur", release);
  document.addEventListener("visibilitychange", function () { if (document.hidden) release(); });
  window.addEventListener("pagehide", release);

  // --- forms that only htmx triggers (data-no-submit): Enter in a field submits nothing (in place of
  // an hx-on attribute, which the Content-Security-Policy's script-src 'self' does not run)
  document.addEventListener("submit", function (event) {
    if (event.target.closest("[data-no-submit]")) event.preventDefault();
  });

  // --- feed override: show the value while the slider moves
  document.addEventListener("input", function (event) {
    if (event.target.id !== "override") return;
    var out = document.getElementById("override-value");
    if (out) out.textContent = event.target.value + " %";
  });
})();
