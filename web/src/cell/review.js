// The plan's review panel (the user interface D3.1 asks for): the task list as a table, the
// robot's and the person's lanes as a timeline, each task coloured by what the cell reported
// (done, failed, started) and the current one outlined; with the server's token, a task is
// switched between the robot and a person from its row or from the 3D view's pick panel, and
// the re-plan shows the times before and after and what changed performer (/api/replan).
//
// The token is asked once and kept in sessionStorage: for this tab only, gone when it closes.
// Without it (or when the server takes no changes) the panel is read-only and says why.

import * as THREE from "three";
import { EndpointError, getJson } from "../api.js";

const $ = (id) => document.getElementById(id);
const KEY = "cadkg.token";
export const STATUS_COLOURS = {
  done: new THREE.Color("#16a34a"),
  failed: new THREE.Color("#dc2626"),
  started: new THREE.Color("#f59e0b"),
};
const OTHER = { robot: "human", human: "robot" };
const WHO = { robot: "the robot", human: "a person" };

const seconds = (value) => (Number.isFinite(value) ? `${Math.round(value)} s` : "–");

export class PlanReview {
  constructor(plan) {
    this.plan = plan;
    this.writable = false;
    this.reason = "";
    $("plan-unlock").addEventListener("click", () => this.unlock());
    $("plan-token").addEventListener("keydown", (e) => { if (e.key === "Enter") this.unlock(); });
    $("plan-forget").addEventListener("click", () => { sessionStorage.removeItem(KEY); this.access(); });
    $("pick-switch").addEventListener("click", () => {
      const step = this.stepOf(this.plan.view.picked);
      if (step) this.switchTask(step);
    });
  }

  /** What the server takes: changes need --allow-update and --token (/api/info). */
  async start() {
    try {
      const info = await getJson("/api/info");
      this.accepts = Boolean(info.update && info.token);
    } catch (err) {
      this.accepts = false;
    }
    this.access();
  }

  access() {
    const token = sessionStorage.getItem(KEY);
    this.writable = this.accepts && Boolean(token);
    if (!this.accepts) {
      this.reason = "Read-only: this server takes no changes (start it with cadkg serve STORE --allow-update --token TOKEN).";
    } else if (!token) {
      this.reason = "Read-only until you give the server's token: it is kept for this tab only.";
    } else {
      this.reason = "";
    }
    $("plan-access").textContent = this.reason || "Changes with the token (kept for this tab only).";
    $("plan-review").dataset.writable = String(this.writable);
    $("plan-login").hidden = !this.accepts || Boolean(token);
    $("plan-forget").hidden = !this.writable;
    for (const button of $("plan-table").querySelectorAll("button")) this.allow(button);
    this.showPick(this.plan.view.picked);
  }

  allow(button) {
    button.disabled = !this.writable;
    button.title = this.writable ? button.dataset.what : this.reason;
  }

  unlock() {
    const token = $("plan-token").value.trim();
    if (!token) return;
    sessionStorage.setItem(KEY, token);
    $("plan-token").value = "";
    this.access();
  }

  /** The whole panel from the plan's steps and summary. */
  show() {
    const { steps, summary } = this.plan;
    // What each drawn thing is the task of, asked per pick and per mark: found once here.
    this.byThing = new Map();
    for (const step of steps) {
      const thing = this.plan.thingOf(step);
      if (thing && !this.byThing.has(thing)) this.byThing.set(thing, step);
    }
    $("plan-review").hidden = false;
    $("plan-times").textContent = `robot ${seconds(summary.robot_time_s)}, person ${seconds(summary.person_time_s)}, `
      + `makespan ${seconds(summary.makespan_s)} side by side`;
    const body = $("plan-table").tBodies[0];
    body.replaceChildren();
    for (const [index, step] of steps.entries()) {
      const row = body.insertRow();
      row.dataset.key = step.key;
      row.className = `status-${step.status || "pending"}`;
      const when = `${seconds(step.start_s)}–${seconds(step.end_s)}`;
      for (const text of [step.step + 1, step.task, step.performer, when, step.status || "pending"]) {
        row.insertCell().textContent = String(text);
      }
      row.cells[1].title = step.reason;
      const button = document.createElement("button");
      button.type = "button";
      button.className = "quiet small";
      button.dataset.key = step.key;
      button.dataset.what = `Give ${step.task} to ${WHO[OTHER[step.performer]]} and plan again`;
      button.textContent = `→ ${OTHER[step.performer]}`;
      button.addEventListener("click", (event) => { event.stopPropagation(); this.switchTask(step); });
      this.allow(button);
      row.insertCell().appendChild(button);
      row.addEventListener("click", () => this.plan.go(index));
    }
    this.lanes(steps, summary);
    this.colour();
    this.current(steps[this.plan.index]);
  }

  /** The two lanes: each task a block from its start to its end, on one time axis. */
  lanes(steps, summary) {
    const span = Math.max(summary.makespan_s || 0, ...steps.map((s) => s.end_s || 0)) || 1;
    for (const lane of ["robot", "human"]) {
      const row = $(`plan-lane-${lane}`);
      row.replaceChildren();
      for (const [index, step] of steps.entries()) {
        if (step.performer !== lane || !Number.isFinite(step.start_s)) continue;
        const block = document.createElement("span");
        block.className = `block status-${step.status || "pending"}`;
        block.dataset.key = step.key;
        block.style.left = `${(100 * step.start_s) / span}%`;
        block.style.width = `${Math.max((100 * (step.end_s - step.start_s)) / span, 0.2)}%`;
        block.title = `${step.task}: ${seconds(step.start_s)}–${seconds(step.end_s)} (${step.status || "pending"})`;
        block.addEventListener("click", () => this.plan.go(index));
        row.appendChild(block);
      }
    }
  }

  /** Done, failed and started tasks marked in the 3D view in their colours. */
  colour() {
    const marks = [];
    for (const [thing, step] of this.byThing) {
      const colour = STATUS_COLOURS[step.status];
      if (colour) marks.push({ thing, colour, status: step.status });
    }
    this.plan.view.markers.set("progress", marks);
    this.plan.view.container.dataset.progress = marks.map((m) => `${m.thing.iri || m.thing.label}=${m.status}`).join(" ");
  }

  /** The current step outlined in the table and the lanes. */
  current(step) {
    for (const element of $("plan-review").querySelectorAll(".current")) element.classList.remove("current");
    if (!step) return;
    for (const element of $("plan-review").querySelectorAll(`[data-key="${CSS.escape(step.key)}"]`)) {
      if (element.tagName !== "BUTTON") element.classList.add("current");
    }
    const row = $("plan-table").querySelector(`tr.current`);
    if (row) row.scrollIntoView({ block: "nearest" });
  }

  /** The step whose task is the thing picked in the 3D view, or null. */
  stepOf(thing) {
    return (thing && this.byThing && this.byThing.get(thing)) || null;
  }

  /** The pick panel's switch button, for a picked thing that is a task of the plan. */
  showPick(thing) {
    const step = this.stepOf(thing);
    const button = $("pick-switch");
    button.hidden = !step;
    if (!step) return;
    button.dataset.what = `Give ${step.task} to ${WHO[OTHER[step.performer]]} and plan again`;
    button.textContent = `${step.performer}'s: give to ${WHO[OTHER[step.performer]]}`;
    this.allow(button);
  }

  async switchTask(step) {
    if (!this.writable) return;
    const performer = OTHER[step.performer];
    delete $("plan-replan").dataset.moved;
    $("plan-replan").textContent = `Planning again with ${step.task} given to ${WHO[performer]} ...`;
    $("plan-replan").hidden = false;
    let answer;
    try {
      answer = await this.post("/api/replan", { task: step.key, performer });
    } catch (err) {
      $("plan-replan").textContent = `Not planned again: ${err.message}`;
      $("plan-replan").dataset.failed = "true";
      return;
    }
    delete $("plan-replan").dataset.failed;
    this.plan.replace(answer);
    this.describe(step, performer, answer);
  }

  /** What the re-plan did: the times before and after, what changed performer. */
  describe(step, performer, answer) {
    const times = ["robot_time_s", "person_time_s", "makespan_s"].map((name, n) => {
      const label = ["robot", "person", "makespan"][n];
      return `${label} ${seconds(answer[`${name}_before`])} → ${seconds(answer[name])}`;
    });
    const moved = answer.moved.map((m) => `${m.task} (${m.before || "new"} → ${m.after})`);
    $("plan-replan").textContent = `${step.task} given to ${WHO[performer]}: ${times.join(", ")}; `
      + `${moved.length} task(s) changed performer: ${moved.join(", ") || "none"}`;
    $("plan-replan").dataset.moved = answer.moved.map((m) => m.key).join(" ");
  }

  async post(url, params) {
    let response;
    try {
      response = await fetch(url, {
        method: "POST",
        headers: { Accept: "application/json", Authorization: `Bearer ${sessionStorage.getItem(KEY)}` },
        body: new URLSearchParams(params),
      });
    } catch (err) {
      throw new EndpointError(`cannot reach the endpoint: ${err.message}`);
    }
    const data = await response.json().catch(() => ({}));
    if (response.status === 401) {
      sessionStorage.removeItem(KEY);
      this.access();
      throw new EndpointError("the server refused the token: give it again");
    }
    if (!response.ok) throw new EndpointError(data.error || `${response.status} ${response.statusText}`);
    return data;
  }
}
