// The SPARQL editor: CodeMirror 6 with the SPARQL mode of @codemirror/legacy-modes, the
// workbench's completions, Ctrl+Enter to run, Tab to indent (Escape then Tab leaves).
// It lives in a shadow root: there CodeMirror styles itself through constructed style sheets
// instead of a <style> element, which the page's Content-Security-Policy (its own files only)
// refuses.

import { autocompletion, closeBrackets, closeBracketsKeymap, completionKeymap } from "@codemirror/autocomplete";
import { defaultKeymap, history, historyKeymap, indentWithTab } from "@codemirror/commands";
import { HighlightStyle, StreamLanguage, bracketMatching, indentOnInput, syntaxHighlighting } from "@codemirror/language";
import { sparql } from "@codemirror/legacy-modes/mode/sparql";
import { highlightSelectionMatches, searchKeymap } from "@codemirror/search";
import { EditorState, Prec } from "@codemirror/state";
import {
  EditorView, drawSelection, highlightActiveLine, highlightActiveLineGutter, keymap, lineNumbers,
} from "@codemirror/view";
import { tags } from "@lezer/highlight";

const style = HighlightStyle.define([
  { tag: tags.keyword, color: "#7c3aed", fontWeight: "600" },
  { tag: [tags.atom, tags.url], color: "#2457c5" },
  { tag: tags.local(tags.variableName), color: "#b45309" },
  { tag: tags.string, color: "#15803d" },
  { tag: tags.comment, color: "#667085", fontStyle: "italic" },
  { tag: tags.standard(tags.variableName), color: "#0e7490" },
  { tag: tags.meta, color: "#9333ea" },
  { tag: tags.number, color: "#be123c" },
  { tag: tags.operator, color: "#475467" },
]);

const theme = EditorView.theme({
  // As tall as its box (the page's #query: resizable, 18rem at first), scrolling inside it, so a
  // long named query never pushes the results below the fold.
  "&": { fontSize: "13px", border: "1px solid var(--line)", borderRadius: "4px", background: "#fff", height: "100%" },
  "&.cm-focused": { outline: "2px solid #b6c8f0" },
  ".cm-scroller": { fontFamily: "ui-monospace, Menlo, Consolas, monospace", lineHeight: "1.45", overflow: "auto" },
  ".cm-content": { minHeight: "15rem" },
  ".cm-gutters": { background: "#f7f8fa", color: "#98a2b3", border: "none" },
  ".cm-tooltip-autocomplete ul li[aria-selected]": { background: "#2457c5", color: "#fff" },
  ".cm-completionDetail": { color: "#667085", fontStyle: "normal", marginLeft: "0.8em" },
});

/** A CodeMirror editor in `parent`; `onRun()` on Ctrl/Cmd+Enter, `onChange(text)` on every edit. */
export function createEditor(parent, { doc = "", completion, onRun, onChange }) {
  const run = () => {
    onRun();
    return true;
  };
  const root = parent.attachShadow({ mode: "open" });
  return new EditorView({
    parent: root,
    root,
    state: EditorState.create({
      doc,
      extensions: [
        lineNumbers(),
        highlightActiveLineGutter(),
        history(),
        drawSelection(),
        indentOnInput(),
        bracketMatching(),
        closeBrackets(),
        highlightActiveLine(),
        highlightSelectionMatches(),
        StreamLanguage.define(sparql),
        syntaxHighlighting(style),
        autocompletion({ override: [completion], activateOnTyping: true, maxRenderedOptions: 80 }),
        Prec.highest(keymap.of([{ key: "Mod-Enter", run }])),
        keymap.of([...closeBracketsKeymap, ...defaultKeymap, ...searchKeymap, ...historyKeymap,
          ...completionKeymap, indentWithTab]),
        EditorView.contentAttributes.of({ "aria-label": "SPARQL query", spellcheck: "false" }),
        EditorView.updateListener.of((update) => {
          if (update.docChanged) onChange(update.state.doc.toString());
        }),
        theme,
      ],
    }),
  });
}

/** Replace the whole text of the editor. */
export function setText(view, text) {
  view.dispatch({ changes: { from: 0, to: view.state.doc.length, insert: text } });
}
