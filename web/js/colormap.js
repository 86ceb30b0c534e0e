// Colour ramps for the field displays: a perceptually ordered blue-to-red ramp (the paper's
// fig. 5 colours: red for the highest tension, blue for the lowest) and a red-to-yellow ramp
// for depth (fig. 5 middle: skin red = depth 0, inner layer yellow = depth 1).
const RAMPS = {
  tension: [[0.23, 0.30, 0.75], [0.55, 0.69, 0.99], [0.87, 0.87, 0.87], [0.96, 0.60, 0.48], [0.71, 0.02, 0.15]],
  depth: [[0.85, 0.10, 0.10], [0.95, 0.50, 0.10], [1.0, 0.90, 0.20]],
};

export function rampColor(name, t) {
  const stops = RAMPS[name];
  const x = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0)) * (stops.length - 1);
  const i = Math.min(stops.length - 2, Math.floor(x));
  const f = x - i;
  return stops[i].map((c, k) => c + f * (stops[i + 1][k] - c));
}

export function rampCss(name) {
  const stops = RAMPS[name].map((c, i, a) => `rgb(${c.map((v) => Math.round(v * 255)).join(',')}) ${(100 * i) / (a.length - 1)}%`);
  return `linear-gradient(to right, ${stops.join(', ')})`;
}
