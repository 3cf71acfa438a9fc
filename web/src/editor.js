// The model editor: CodeMirror 6 with TOML highlighting, and a loader's error shown where it
// is — the line marked, the column's character underlined, the cursor moved there.
import { Compartment, EditorState, StateEffect, StateField } from "@codemirror/state";
import { EditorView, Decoration, keymap, lineNumbers, highlightActiveLine } from "@codemirror/view";
import { defaultKeymap, history, historyKeymap } from "@codemirror/commands";
import { StreamLanguage, syntaxHighlighting, defaultHighlightStyle } from "@codemirror/language";
import { toml } from "@codemirror/legacy-modes/mode/toml";
import { shell } from "@codemirror/legacy-modes/mode/shell";

// A model file is TOML; a script of `pdyn kin`/`pdyn dsolve` lines is shell.
const LANGUAGES = {
  toml: { mode: StreamLanguage.define(toml), label: "Model file (TOML)" },
  shell: { mode: StreamLanguage.define(shell), label: "Script of pdyn kin and pdyn dsolve command lines" },
};

const setError = StateEffect.define();

const errorField = StateField.define({
  create: () => Decoration.none,
  update(deco, tr) {
    deco = deco.map(tr.changes);
    for (const e of tr.effects) if (e.is(setError)) deco = e.value;
    // Editing clears the mark: it described the text as it was.
    return tr.docChanged ? Decoration.none : deco;
  },
  provide: (f) => EditorView.decorations.from(f),
});

export function createEditor(parent, onChange) {
  const language = new Compartment();
  let current = "toml";
  const view = new EditorView({
    parent,
    state: EditorState.create({
      doc: "",
      extensions: [
        lineNumbers(),
        history(),
        highlightActiveLine(),
        keymap.of([...defaultKeymap, ...historyKeymap]),
        language.of([LANGUAGES.toml.mode, EditorView.contentAttributes.of({ "aria-label": LANGUAGES.toml.label })]),
        syntaxHighlighting(defaultHighlightStyle),
        errorField,
        EditorView.lineWrapping,
        EditorView.updateListener.of((u) => u.docChanged && onChange?.()),
      ],
    }),
  });
  return {
    view,
    get text() {
      return view.state.doc.toString();
    },
    set text(t) {
      view.dispatch({ changes: { from: 0, to: view.state.doc.length, insert: t } });
    },
    /** "toml" (a model) or "shell" (a script of command lines): highlighting and label. */
    set language(name) {
      if (name === current || !(name in LANGUAGES)) return;
      current = name;
      const l = LANGUAGES[name];
      view.dispatch({ effects: language.reconfigure([l.mode, EditorView.contentAttributes.of({ "aria-label": l.label })]) });
    },
    get language() {
      return current;
    },
    /** Marks line `line` (1-based) and the character at `column` (1-based). */
    markError(line, column) {
      const doc = view.state.doc;
      if (!(line >= 1 && line <= doc.lines)) return false;
      const l = doc.line(line);
      const at = Math.min(l.from + Math.max(0, (column || 1) - 1), l.to);
      const marks = [Decoration.line({ class: "cm-error-line" }).range(l.from)];
      if (at < l.to) marks.push(Decoration.mark({ class: "cm-error-mark" }).range(at, Math.min(l.to, at + 1)));
      view.dispatch({
        effects: [setError.of(Decoration.set(marks, true)), EditorView.scrollIntoView(at, { y: "center" })],
        selection: { anchor: at },
      });
      return true;
    },
    clearError() {
      view.dispatch({ effects: setError.of(Decoration.none) });
    },
  };
}
