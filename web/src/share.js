// The model travels in the URL's fragment (never sent to a server): `#model=` the text,
// deflated and base64url-encoded, so a link reproduces it; `#example=` names a shipped one.
async function transform(bytes, stream) {
  const out = new Blob([bytes]).stream().pipeThrough(stream);
  return new Uint8Array(await new Response(out).arrayBuffer());
}

function toBase64Url(bytes) {
  let s = "";
  for (const b of bytes) s += String.fromCharCode(b);
  return btoa(s).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
}

function fromBase64Url(text) {
  const b64 = text.replace(/-/g, "+").replace(/_/g, "/");
  const s = atob(b64 + "=".repeat((4 - (b64.length % 4)) % 4));
  return Uint8Array.from(s, (c) => c.charCodeAt(0));
}

export async function encodeModel(text) {
  const packed = await transform(new TextEncoder().encode(text), new CompressionStream("deflate-raw"));
  return toBase64Url(packed);
}

export async function decodeModel(code) {
  const bytes = await transform(fromBase64Url(code), new DecompressionStream("deflate-raw"));
  return new TextDecoder().decode(bytes);
}

/** {model?: string, example?: string} from location.hash. */
export async function readHash(hash) {
  const params = new URLSearchParams(hash.replace(/^#/, ""));
  const out = {};
  if (params.has("example")) out.example = params.get("example");
  if (params.has("model")) {
    try {
      out.model = await decodeModel(params.get("model"));
    } catch (err) {
      out.error = `the link's model could not be read (${err.message}); the link may be cut short`;
    }
  }
  return out;
}
