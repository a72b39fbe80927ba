// Query tabs: each keeps its text and its named query (name, parameters, the VALUES block
// bound into the text). They live in local storage, so a reload loses nothing, and the
// active tab's query is in the URL (#query=...), so a link opens it elsewhere.

const KEY = "cadkg.workbench.tabs.v1";

export class Tabs {
  constructor({ starter, onSwitch }) {
    this.onSwitch = onSwitch;
    this.tabs = [];
    this.active = null;
    this.serial = 0;
    try {
      const saved = JSON.parse(localStorage.getItem(KEY) || "null");
      if (saved && Array.isArray(saved.tabs) && saved.tabs.length) {
        this.tabs = saved.tabs.filter((t) => typeof t.text === "string");
        this.serial = saved.serial || this.tabs.length;
        this.active = this.tabs.find((t) => t.id === saved.active) || this.tabs[0];
      }
    } catch (err) {
      /* storage unavailable or unreadable: start afresh */
    }
    if (!this.tabs.length) this.active = this.add(starter, null, false);
  }

  add(text, named = null, switchTo = true, title = null) {
    this.serial += 1;
    const tab = {
      id: `t${this.serial}`, title: title || (named ? named.name : `Query ${this.serial}`), text, named, pristine: text,
    };
    this.tabs.push(tab);
    if (switchTo) this.select(tab.id);
    this.save();
    return tab;
  }

  select(id) {
    const tab = this.tabs.find((t) => t.id === id);
    if (!tab) return;
    this.active = tab;
    this.save();
    this.onSwitch(tab);
  }

  close(id) {
    if (this.tabs.length === 1) return;
    const index = this.tabs.findIndex((t) => t.id === id);
    this.tabs.splice(index, 1);
    if (this.active.id === id) this.select(this.tabs[Math.max(0, index - 1)].id);
    this.save();
  }

  update(changes) {
    Object.assign(this.active, changes);
    this.save();
  }

  save() {
    clearTimeout(this.timer);
    this.timer = setTimeout(() => {
      try {
        localStorage.setItem(KEY, JSON.stringify({ tabs: this.tabs, active: this.active.id, serial: this.serial }));
      } catch (err) {
        /* storage full or off: tabs last this page only */
      }
    }, 200);
  }

  /** Open the query a link carries (in a tab of its own, or the tab that already holds it). */
  openLink(hash) {
    const params = new URLSearchParams(hash.replace(/^#/, ""));
    const text = params.get("query");
    if (!text) return null;
    let named = null;
    if (params.get("named")) {
      const values = {};
      for (const [key, value] of params) if (key.startsWith("p.")) values[key.slice(2)] = value;
      named = { name: params.get("named"), params: values, values: params.get("values") || "" };
    }
    const existing = this.tabs.find((t) => t.text === text);
    if (existing) {
      existing.named = named;
      this.select(existing.id);
      return existing;
    }
    return this.add(text, named, true, named ? named.name : "Shared query");
  }
}

/** The link of a query (and of its named query's parameters) on this page. */
export function permalink(tab) {
  const params = new URLSearchParams({ query: tab.text });
  if (tab.named) {
    params.set("named", tab.named.name);
    params.set("values", tab.named.values || "");
    for (const [key, value] of Object.entries(tab.named.params || {})) params.set(`p.${key}`, value);
  }
  return `${location.origin}${location.pathname}#${params}`;
}
