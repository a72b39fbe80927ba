// The robot's task list in the 3D view (/api/plan, made by `cadkg plan`): step through it, the
// current task picked (highlighted, its facts shown) and the next NEXT tasks marked in a dim
// blue. An operation is drawn as what it works on (./tasks.js: its jigs, guides, spots and
// cables); any other task where its name, or a word of it, names something drawn: a wire by its
// number, a component, a jig, a guide or a spot.

import * as THREE from "three";
import { getJson, postQuery } from "../api.js";
import { prefixes } from "../prefixes.js";
import { PlanReview } from "./review.js";
import { pieces, taskThings } from "./tasks.js";

const $ = (id) => document.getElementById(id);
const NEXT = 5;
const DIM = new THREE.Color("#8fa9e0");

export class PlanSteps {
  constructor(view) {
    this.view = view;
    this.steps = null;
    this.tasks = new Map();
    this.index = 0;
    this.review = new PlanReview(this);
    $("cell-plan-toggle").addEventListener("click", () => this.toggle());
    $("plan-prev").addEventListener("click", () => this.go(this.index - 1));
    $("plan-next").addEventListener("click", () => this.go(this.index + 1));
    $("plan-first").addEventListener("click", () => this.go(0));
  }

  async toggle() {
    const bar = $("plan-bar");
    if (!bar.hidden) {
      bar.hidden = true;
      $("plan-review").hidden = true;
      $("cell-plan-toggle").classList.remove("active");
      this.view.markers.set("plan", []);
      this.view.markers.set("progress", []);
      return;
    }
    bar.hidden = false;
    $("cell-plan-toggle").classList.add("active");
    if (!this.steps) {
      try {
        // Asked first, so a cell without a plan costs no failed request (/api/plan: 404).
        const ask = await (await postQuery(`ASK { GRAPH <${prefixes.cell}plan> { ?s ?p ?o } }`)).json();
        if (!ask.boolean) throw new Error("none yet");
        const plan = await getJson("/api/plan");
        this.tasks = await taskThings(this.view.things, `${prefixes.cell}plan`);
        for (const step of plan.steps) if (this.tasks.has(step.key)) this.tasks.get(step.key).label = step.task;
        this.steps = plan.steps;
        this.summary = plan.summary;
        await this.review.start();
      } catch (err) {
        this.steps = [];
        $("plan-task").textContent = `No plan in this graph: make one with cadkg plan STORE (${err.message})`;
        return;
      }
    }
    this.review.show();
    await this.go(this.index);
  }

  /** The plan a re-plan answered (/api/replan): its steps and summary, shown again. */
  async replace(plan) {
    const key = this.steps[this.index] ? this.steps[this.index].key : null;
    this.steps = plan.steps;
    this.summary = plan.summary;
    const index = this.steps.findIndex((s) => s.key === key);
    this.index = index < 0 ? 0 : index;
    this.review.show();
    await this.go(this.index);
  }

  /** What a task names in the view, or null. */
  thingOf(step) {
    if (this.tasks.has(step.key)) return this.tasks.get(step.key);
    const things = this.view.things;
    const words = [step.task, step.key, ...step.task.split(/\s+/).slice(1)];
    for (const word of words) {
      const thing = things.find(word);
      if (thing) return thing;
    }
    return null;
  }

  async go(index) {
    if (!this.steps || !this.steps.length) return;
    this.index = Math.min(Math.max(index, 0), this.steps.length - 1);
    const step = this.steps[this.index];
    $("plan-step").textContent = `step ${step.step + 1} of ${this.steps.length}`;
    const tool = step.tool ? ` with ${step.tool}` : "";
    $("plan-task").textContent = `${step.task} (${step.kind}) · ${step.performer}${tool} · ${step.placement}`;
    $("plan-task").title = step.reason;
    $("plan-prev").disabled = this.index === 0;
    $("plan-next").disabled = this.index === this.steps.length - 1;
    const next = this.steps.slice(this.index + 1, this.index + 1 + NEXT).map((s) => this.thingOf(s)).filter(Boolean);
    const current = this.thingOf(step);
    this.view.container.dataset.planStep = String(step.step);
    this.view.container.dataset.planNext = next.map((t) => t.iri || t.label).join(" ");
    this.view.container.dataset.planParts = current ? pieces(current).map((t) => t.label).join("|") : "";
    this.view.markers.set("plan", next.filter((t) => t !== current).map((thing) => ({ thing, colour: DIM })));
    this.review.current(step);
    if (current) {
      await this.view.select(current);
    } else {
      await this.view.select(null);
      $("cell-status").textContent = `step ${step.step + 1}: ${step.task} is not drawn in the 3D view`;
    }
  }
}
