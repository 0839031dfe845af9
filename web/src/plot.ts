// Thin helpers over uPlot: a time plot of a fixed size whose data is replaced.
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';

export const COLORS = ['#1f5fbf', '#d9480f', '#2b8a3e', '#7048e8', '#c2255c', '#0b7285', '#e67700', '#495057'];

export interface SeriesSpec {
  label: string;
  color?: string;
  scale?: string;
  dash?: number[];
  width?: number;
}

export interface PlotSpec {
  title?: string;
  ylabel?: string;
  y2label?: string; // a second axis on the right for the series whose scale is 'y2'
  xlabel?: string; // default 't [s]'
  xlog?: boolean; // logarithmic x axis (Bode plots)
  series: SeriesSpec[];
  width?: number;
  height?: number;
}

export function plotWidth(el: HTMLElement): number {
  return Math.max(400, Math.min(920, el.clientWidth || 800));
}

export class TimePlot {
  private plot: uPlot | null = null;
  private key = '';

  constructor(private readonly el: HTMLElement) {}

  // Draws the data; a plot of the same series is reused (setData), anything else rebuilt.
  draw(spec: PlotSpec, data: (number | null)[][]): void {
    const key = JSON.stringify(spec);
    if (this.plot && key === this.key) {
      this.plot.setData(data as uPlot.AlignedData);
      return;
    }
    this.destroy();
    this.key = key;
    // the axis names (drawn on the canvas) for scripts and tests
    this.el.dataset.ylabel = spec.ylabel ?? '';
    this.el.dataset.y2label = spec.y2label ?? '';
    const axes: uPlot.Axis[] = [
      { label: spec.xlabel ?? 't [s]' },
      { label: spec.ylabel ?? '', scale: 'y' },
    ];
    const scales: uPlot.Scales = { x: { time: false, distr: spec.xlog ? 3 : 1 }, y: {} };
    const hooks: uPlot.Hooks.Arrays = {};
    if (spec.y2label !== undefined) {
      // uPlot turns a right-hand label to read downwards ("[%] u" from below):
      // the axis keeps the space and the label is drawn reading upwards, as the left one.
      axes.push({ label: ' ', scale: 'y2', side: 1, grid: { show: false } });
      scales.y2 = {};
      const text = spec.y2label;
      hooks.draw = [(u: uPlot) => {
        const ctx = u.ctx;
        const dpr = window.devicePixelRatio || 1;
        ctx.save();
        ctx.font = `bold ${12 * dpr}px system-ui, sans-serif`;
        ctx.fillStyle = '#000';
        ctx.textAlign = 'center';
        ctx.textBaseline = 'bottom';
        ctx.translate(u.ctx.canvas.width - 6 * dpr, u.bbox.top + u.bbox.height / 2);
        ctx.rotate(-Math.PI / 2);
        ctx.fillText(text, 0, 0);
        ctx.restore();
      }];
    }
    const opts: uPlot.Options = {
      title: spec.title,
      width: spec.width ?? plotWidth(this.el),
      height: spec.height ?? 250,
      scales,
      axes,
      legend: { live: true },
      hooks,
      cursor: { drag: { x: true, y: false } },
      series: [
        { label: 't' },
        ...spec.series.map((s, i) => ({
          label: s.label,
          stroke: s.color ?? COLORS[i % COLORS.length],
          width: s.width ?? 1.5,
          scale: s.scale ?? 'y',
          dash: s.dash,
          points: { show: false },
        })),
      ],
    };
    this.plot = new uPlot(opts, data as uPlot.AlignedData, this.el);
  }

  destroy(): void {
    if (this.plot) {
      this.plot.destroy();
      this.plot = null;
    }
    this.el.innerHTML = '';
    this.key = '';
  }
}

// Linear interpolation of (xs, ys) at the points xq (xs increasing).
export function interp(xs: number[], ys: number[], xq: number[]): (number | null)[] {
  const out: (number | null)[] = new Array(xq.length);
  let j = 0;
  for (let i = 0; i < xq.length; i++) {
    const x = xq[i];
    if (xs.length === 0 || x < xs[0] || x > xs[xs.length - 1]) {
      out[i] = null;
      continue;
    }
    while (j + 1 < xs.length && xs[j + 1] < x) j++;
    if (j + 1 >= xs.length || xs[j + 1] === xs[j]) {
      out[i] = ys[j];
    } else {
      const a = (x - xs[j]) / (xs[j + 1] - xs[j]);
      out[i] = a <= 0 ? ys[j] : a >= 1 ? ys[j + 1] : ys[j] + a * (ys[j + 1] - ys[j]);
    }
  }
  return out;
}
