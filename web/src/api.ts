// The HTTP JSON API of `pneumid app` (docs/app.md). Every call carries the
// page's token, as the header X-Pneumid-Token and the query parameter token=.

export const token: string = new URLSearchParams(location.search).get('token') ?? '';

export class ApiError extends Error {
  constructor(message: string, readonly status: number) {
    super(message);
  }
}

export function withToken(path: string): string {
  return path + (path.includes('?') ? '&' : '?') + 'token=' + encodeURIComponent(token);
}

interface CallOptions {
  body?: unknown;
  raw?: BodyInit;
  contentType?: string;
  signal?: AbortSignal;
  as?: 'json' | 'text' | 'blob';
}

export async function call<T = any>(method: string, path: string, opts: CallOptions = {}): Promise<T> {
  const headers: Record<string, string> = { 'X-Pneumid-Token': token };
  let body: BodyInit | undefined;
  if (opts.raw !== undefined) {
    body = opts.raw;
    headers['Content-Type'] = opts.contentType ?? 'application/octet-stream';
  } else if (opts.body !== undefined) {
    body = JSON.stringify(opts.body);
    headers['Content-Type'] = 'application/json';
  }
  let res: Response;
  try {
    res = await fetch(withToken(path), { method, headers, body, signal: opts.signal });
  } catch (e) {
    if ((e as Error).name === 'AbortError') throw e;
    throw new ApiError(`${method} ${path}: the server does not answer (${(e as Error).message})`, 0);
  }
  if (!res.ok) {
    let message = `${res.status} ${res.statusText}`;
    const text = await res.text();
    try {
      const j = JSON.parse(text);
      if (j && typeof j.error === 'string') message = j.error;
    } catch {
      if (text) message += ': ' + text.slice(0, 300);
    }
    throw new ApiError(`${method} ${path.split('?')[0]}: ${message}`, res.status);
  }
  if (opts.as === 'text') return (await res.text()) as T;
  if (opts.as === 'blob') return (await res.blob()) as T;
  return (await res.json()) as T;
}

export function streamUrl(path: string): string {
  const proto = location.protocol === 'https:' ? 'wss:' : 'ws:';
  return proto + '//' + location.host + withToken(path);
}

export interface DataSet {
  id: string;
  name: string;
  columns: string[];
  t: string;
  u: string;
  y: string;
  samples: number;
  Ts: number;
  signals: { t: number[]; u: number[]; y: number[] };
  decimated?: boolean;
}

export interface ModelSummary {
  method: string;
  structure: string;
  fit_percent: number;
  flags: (string | { flag: string; reason?: string })[];
}

export interface ModelEntry {
  method: string;
  structure?: string;
  fit_percent?: number;
  params?: Record<string, unknown>;
  flags?: (string | { flag: string; reason?: string })[];
  [key: string]: unknown;
}

export interface IdentifyResult {
  models: ModelSummary[];
  best?: string;
  failures?: unknown[];
  /** What the held-out part cannot tell (e.g. a constant input), one sentence each. */
  warnings?: string[];
  responses?: Record<string, number[]>;
  model_file?: { models: ModelEntry[]; best?: string; [key: string]: unknown };
}
