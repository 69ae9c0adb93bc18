// UTF-8 TextDecoder and TextEncoder where the scope lacks them (an AudioWorkletGlobalScope in
// some browsers): the WebAssembly glue decodes the engine's messages and encodes a model's text
// with them. Imported before the glue, so that they exist when it starts. Only what the glue
// uses: decode(bytes) and encode(string).

if (typeof globalThis.TextDecoder === "undefined") {
  globalThis.TextDecoder = class TextDecoder {
    decode(bytes) {
      if (!bytes) return "";
      const view = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes.buffer ?? bytes);
      let text = "";
      let i = 0;
      while (i < view.length) {
        const lead = view[i];
        let code;
        let extra;
        if (lead < 0x80) [code, extra] = [lead, 0];
        else if (lead >= 0xf0) [code, extra] = [lead & 0x07, 3];
        else if (lead >= 0xe0) [code, extra] = [lead & 0x0f, 2];
        else if (lead >= 0xc0) [code, extra] = [lead & 0x1f, 1];
        else [code, extra] = [0xfffd, 0];
        i += 1;
        for (let k = 0; k < extra && i < view.length; k += 1, i += 1) {
          code = (code << 6) | (view[i] & 0x3f);
        }
        text += String.fromCodePoint(code);
      }
      return text;
    }
  };
}

if (typeof globalThis.TextEncoder === "undefined") {
  globalThis.TextEncoder = class TextEncoder {
    encode(text = "") {
      const bytes = [];
      for (const character of text) {
        let code = character.codePointAt(0);
        // A lone surrogate is no character: U+FFFD, as the platform's encoder writes it.
        if (code >= 0xd800 && code <= 0xdfff) code = 0xfffd;
        if (code < 0x80) bytes.push(code);
        else if (code < 0x800) bytes.push(0xc0 | (code >> 6), 0x80 | (code & 0x3f));
        else if (code < 0x10000) {
          bytes.push(0xe0 | (code >> 12), 0x80 | ((code >> 6) & 0x3f), 0x80 | (code & 0x3f));
        } else {
          bytes.push(
            0xf0 | (code >> 18),
            0x80 | ((code >> 12) & 0x3f),
            0x80 | ((code >> 6) & 0x3f),
            0x80 | (code & 0x3f),
          );
        }
      }
      return new Uint8Array(bytes);
    }
  };
}
