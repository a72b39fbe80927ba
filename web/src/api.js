// Requests to the endpoint this page came from (nothing else is ever fetched).

export const RESULTS_ACCEPT = "application/sparql-results+json, application/n-triples;q=0.9";

export class EndpointError extends Error {}

async function failure(response) {
  const body = await response.text();
  let message = body;
  try {
    message = JSON.parse(body).error || body;
  } catch (err) {
    /* a plain-text error */
  }
  return new EndpointError(`${response.status} ${response.statusText}\n${message}`.trim());
}

export async function getJson(url) {
  let response;
  try {
    response = await fetch(url, { headers: { Accept: "application/json" } });
  } catch (err) {
    throw new EndpointError(`cannot reach the endpoint: ${err.message}`);
  }
  if (!response.ok) throw await failure(response);
  return response.json();
}

/** POST a query to /sparql; `format` (csv, ttl ...) asks for a download format instead of Accept. */
export async function postQuery(text, { accept = RESULTS_ACCEPT, format = null } = {}) {
  const body = new URLSearchParams({ query: text });
  if (format) body.set("format", format);
  let response;
  try {
    response = await fetch("/sparql", {
      method: "POST",
      headers: { Accept: accept, "Content-Type": "application/x-www-form-urlencoded" },
      body: body.toString(),
    });
  } catch (err) {
    throw new EndpointError(`cannot reach the endpoint: ${err.message}`);
  }
  if (!response.ok) throw await failure(response);
  return response;
}

/** Save a response body as a file of the user's (through a link to its blob, clicked). */
export async function saveResponse(response, filename) {
  const blob = await response.blob();
  const url = URL.createObjectURL(blob);
  const link = document.createElement("a");
  link.href = url;
  link.download = filename;
  document.body.appendChild(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}
