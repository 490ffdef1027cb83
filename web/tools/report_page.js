// In the report page (inlined by report.mjs): draws PLOTS with uPlot and
// exposes window.iplanReport for tests.
(function () {
  const colors = ["#1565c0", "#c62828", "#2e7d32", "#6a1b9a", "#ef6c00", "#00838f", "#5d4037"];
  const drawn = [];
  for (const p of PLOTS) {
    const el = document.getElementById("plot-" + p.id);
    const series = [{ label: p.x }];
    p.series.forEach((s, i) => series.push({ label: s.label, stroke: colors[i % colors.length], scale: s.scale || "y",
      width: 2, spanGaps: !!s.spanGaps, points: { show: !!s.points || !!p.bars },
      fill: p.bars ? colors[i % colors.length] + "88" : undefined,
      paths: p.bars ? uPlot.paths.bars({ size: [0.8, 60] }) : undefined }));
    const x = { label: p.x };
    if (p.xlabels) {
      x.splits = () => p.xs;
      x.values = (u, ticks) => ticks.map((t) => p.xlabels[Math.round(t) - 1] ?? "");
    } else if (p.integerX) {
      x.splits = () => p.xs;
    }
    const axes = [x, { label: p.y || p.series[0].label }];
    if (p.series.some((s) => s.scale === "p")) axes.push({ scale: "p", side: 1, label: "bound", grid: { show: false } });
    const marks = p.marks || [];
    const opts = { width: 940, height: 260, series, axes, scales: { x: { time: false } },
      hooks: { draw: [(u) => {
        // Stops: a red line at each time the robot was stopped.
        const ctx = u.ctx;
        ctx.save();
        ctx.strokeStyle = "#d32f2f";
        ctx.setLineDash([4, 3]);
        for (const m of marks) {
          const x = u.valToPos(m.t, "x", true);
          ctx.beginPath(); ctx.moveTo(x, u.bbox.top); ctx.lineTo(x, u.bbox.top + u.bbox.height); ctx.stroke();
        }
        ctx.restore();
      }] } };
    new uPlot(opts, [p.xs, ...p.series.map((s) => s.data)], el);
    drawn.push({ id: p.id, title: p.title, points: p.xs.length, series: p.series.length, marks: marks.length });
  }
  window.iplanReport = { ready: true, plots: drawn };
})();
