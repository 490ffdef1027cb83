// The strip above the view: current task, the person's believed action,
// the ISO/TS 15066 separation and verdict, stops and their reasons. Fed with
// the cell's own topics (JSON as the bridge forwards them).
const VERDICTS = ["OK", "SLOW_DOWN", "PROTECTIVE_STOP"];

export const STRIP_TOPICS = ["/iplan/task/command", "/iplan/task/outcome", "/iplan/human/action_belief",
  "/iplan/collision_risk", "/iplan/safety/permit/supervisor", "/iplan/safety/permit/collision_risk",
  "/iplan/robot/plan_status"];

export function emptyStrip() {
  return { task: null, action: null, actionProbability: 0, verdict: null, separation: null, protectiveSeparation: null,
    riskReason: "", stops: 0, stopped: false, lastStopReason: "", stopSources: {}, latency: null };
}

/** Updates strip state `s` with message `m` of `topic`. */
export function applyStrip(s, topic, m) {
  switch (topic) {
    case "/iplan/task/command":
      if (m.command === 0) s.task = m.task_name;
      break;
    case "/iplan/task/outcome":
      if (s.task === m.task_name) s.task = null;
      break;
    case "/iplan/human/action_belief": {
      let best = -1;
      m.probabilities.forEach((p, i) => { if (best < 0 || p > m.probabilities[best]) best = i; });
      if (best >= 0) {
        s.action = m.actions[best];
        s.actionProbability = m.probabilities[best];
      }
      break;
    }
    case "/iplan/collision_risk":
      s.verdict = m.verdict;
      s.separation = typeof m.min_separation === "number" ? m.min_separation : null;
      s.protectiveSeparation = typeof m.protective_separation === "number" ? m.protective_separation : null;
      s.riskReason = m.reason;
      break;
    case "/iplan/safety/permit/supervisor":
    case "/iplan/safety/permit/collision_risk": {
      // The robot stands while any monitor withholds its permit; a stop is
      // counted when the first one does (as iplan demo counts them).
      const was = s.stopped;
      s.stopSources[m.source] = m.state === 0;
      s.stopped = Object.values(s.stopSources).some((v) => v);
      if (s.stopped && !was) {
        s.stops += 1;
        s.lastStopReason = `${m.source}: ${m.reason}`;
      }
      break;
    }
    case "/iplan/robot/plan_status":
      if (m.latency > 0) s.latency = m.latency;
      break;
  }
}

export function renderStrip(s) {
  const $ = (id) => document.getElementById(id);
  $("task").textContent = s.task ?? "-";
  $("action").textContent = s.action ? `${s.action} (${(100 * s.actionProbability).toFixed(0)} %)` : "-";
  const v = $("verdict");
  if (s.verdict === null) {
    v.textContent = "-";
  } else {
    const sep = s.separation === null ? "-" : `${s.separation.toFixed(2)} m`;
    const sp = s.protectiveSeparation === null ? "-" : `${s.protectiveSeparation.toFixed(2)} m`;
    v.textContent = `${VERDICTS[s.verdict] ?? s.verdict}  separation ${sep}, S_p ${sp}`;
    v.className = `verdict-${s.verdict}`;
  }
  $("stops").textContent = `${s.stops}${s.stopped ? " (stopped)" : ""}`;
  $("reason").textContent = s.lastStopReason;
  $("reason").title = s.lastStopReason;
}
