// fieldpath view: the page's colour scales and number formats (app/view/colours.js, inlined by
// `fieldpath view` before view.js): pure functions of their arguments, no page state (they were
// the first hundred lines of view.js, which ran past 850).
var fpColours = (function() {
  'use strict';
  var VIRIDIS = [
    [68, 1, 84], [72, 40, 120], [62, 74, 137], [49, 104, 142], [38, 130, 142], [31, 158, 137],
    [53, 183, 121], [110, 206, 88], [181, 222, 43], [253, 231, 37]
  ];
  function ramp(stops, t) {
    t = Math.min(1, Math.max(0, isFinite(t) ? t : 0)) * (stops.length - 1);
    var i = Math.min(stops.length - 2, Math.floor(t)), f = t - i, a = stops[i], b = stops[i + 1];
    return [
      (a[0] + f * (b[0] - a[0])) / 255, (a[1] + f * (b[1] - a[1])) / 255,
      (a[2] + f * (b[2] - a[2])) / 255
    ];
  }
  var NO_VALUE = [0.55, 0.57, 0.6];
  function sequential(lo, hi) {
    return function(v) {
      return isFinite(v) ? ramp(VIRIDIS, (v - lo) / (hi - lo)) : NO_VALUE;
    };
  }
  // Clearance: red at contact, orange up to the required clearance, then yellow, green, blue.
  var CLEAR_STOPS = [[214, 39, 40], [255, 127, 14], [255, 221, 87], [44, 160, 44], [31, 119, 180]];
  function clearanceMap(required, hi) {
    return function(v) {
      if (!isFinite(v)) return NO_VALUE;
      if (v <= 0) return ramp(CLEAR_STOPS, 0);
      if (v < required) return ramp(CLEAR_STOPS, 0.25 * v / required);
      return ramp(CLEAR_STOPS, 0.25 + 0.75 * (v - required) / Math.max(1e-9, hi - required));
    };
  }
  // Deviation (um): gouge (below the part) blue, on the part white-green, scallop yellow to red.
  var GOUGE_STOPS = [[8, 48, 107], [66, 146, 198], [198, 219, 239]];
  var SCALLOP_STOPS = [[229, 245, 224], [254, 224, 139], [253, 141, 60], [189, 0, 38]];
  var UNCUT = [0.45, 0.45, 0.47];
  // Above the scale (its top: check's max scallop over the machined band), stock left beside the
  // band: its own colour (it read as the worst scallop's red, a newcomer's finding).
  var ABOVE = [0.42, 0.24, 0.6];
  function deviationMap(lo, hi, uncut) {
    return function(v) {
      if (uncut && v >= uncut) return UNCUT;
      if (!isFinite(v)) return null;  // off the part: no triangle
      if (v < 0) return ramp(GOUGE_STOPS, 1 - v / lo);
      if (v > hi) return ABOVE;
      return ramp(SCALLOP_STOPS, v / hi);
    };
  }
  function withUncut(map, uncut) {
    return function(v) {
      return uncut && v >= uncut ? UNCUT : map(v);
    };
  }
  function niceStep(span, count) {
    var raw = span / count, p = Math.pow(10, Math.floor(Math.log10(raw))), m = raw / p;
    return p * (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10);
  }
  function fmt(v, digits) {
    if (v === null || v === undefined || !isFinite(v)) return '\u2014';
    return (Math.abs(v) < 0.5 * Math.pow(10, -digits) ? 0 : v).toFixed(digits);
  }

  return {
    sequential: sequential,
    clearanceMap: clearanceMap,
    deviationMap: deviationMap,
    withUncut: withUncut,
    niceStep: niceStep,
    fmt: fmt,
    NO_VALUE: NO_VALUE
  };
})();
