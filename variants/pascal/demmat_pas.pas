{ DEMMAT_PAS: the arrays processor (variants/arrays) in Object Pascal (Free Pascal, Delphi mode), driven
  from C++ through cdecl exports (pascal.cpp). A port of variants/f90/demmat_f90.f90.

  State: as in the paper's DEMMAT_PAS the particles' state lives in GLOBAL dynamic arrays of Double. So
  that the test suite can hold two live instances at once (save-and-continue, a variant compared with
  itself), the globals are a small global array of MAX_SLOTS records (Slots), each holding its own
  dynamic arrays; a handle is a slot index. demmat_pas_create returns -1 when all slots are taken and the
  C++ wrapper then throws demmat::Error. Not thread-safe (create/destroy touch the global table).

  Layout: each (N, 3) array is column-major, element (i, c) at c*N + i, i and c 0-based.
  Bit identity (physics.md section 6): every expression mirrors common/include/demmat/gear.hpp and contact_law.hpp
  operation for operation, parenthesised in C++'s left-to-right order; h^(3/2) = h*sqrt(h); everything is
  Double evaluated with SSE2 (no x87 Extended: literals are typed Double constants, no float literal
  appears inside an expression); no fast-math, no FMA. Gear coefficients, contact parameters, gravity and
  the may_touch margin 1.000000001 come from C++. Each entry point runs with MXCSR = $1F80 (IEEE default:
  round to nearest, all exceptions masked, no flush-to-zero) and restores the caller's MXCSR on return.

  Search: linked cells over the bounding box with one empty padding layer, falling back to all pairs
  when the direct grid would exceed 8*N + 4096 cells; cell = 0 means all pairs (as the f90 port). }
library demmat_pas;

{$mode delphi}
{$R-}{$Q-}{$J-}

const
  MAX_SLOTS = 8;
  ST_OK = 0; ST_PAIR_CAP = 1; ST_WALL_CAP = 2; ST_RUNAWAY = 3;
  ZERO: Double = 0.0;
  HALF: Double = 0.5;
  THREE: Double = 3.0;
  FOUR: Double = 4.0;
  FIVE: Double = 5.0;
  SIX: Double = 6.0;
  TEN: Double = 10.0;
  BIG: Double = 1099511627776.0;  { 2^40 }

type
  TDArr = array of Double;
  TIArr = array of LongInt;
  TI64Arr = array of Int64;
  PInt64Arr = ^Int64;

  TProc = record
    used: Boolean;
    n, nw, cap, wcap, pcap, pwcap: LongInt;
    cell, margin: Double;
    dt, half_dt2, two_over_dt2, cx, cv, c3, c4, c5, negligible: Double;
    hertz_pp, hertz_pw, gamma_n, gamma_t, mu: Double;
    g: array[0..2] of Double;
    x, v, a, b3, b4, b5, th, w, al, r3, r4, r5, f, t, acc, alc: TDArr;
    r, m, inert: TDArr;
    wp, wn, wv: TDArr;       { 3*nw, (c, w) at 3*w + c }
    ncount, partner: TIArr;  { partner (k, i) at i*pcap + k }
    wcount, wall: TIArr;     { wall (k, i) at i*pwcap + k }
    head, next: TIArr;
    cellidx, cc3: TI64Arr;
    pp, pw, cand: Int64;
  end;

var
  Slots: array[0..MAX_SLOTS - 1] of TProc;

{ ---- FP environment ------------------------------------------------------------------------------- }

function EnterFP: LongWord; inline;
begin
  Result := GetMXCSR;
  SetMXCSR($1F80);
end;

procedure LeaveFP(saved: LongWord); inline;
begin
  SetMXCSR(saved);
end;

{ ---- Gear ---------------------------------------------------------------------------------------- }

procedure GearPredictor(n: LongInt; var x, v, a, b3, b4, b5: TDArr; dt, half_dt2, two_over_dt2: Double);
var k: LongInt;
begin
  for k := 0 to 3 * n - 1 do
  begin
    x[k] := ((((x[k] + dt * v[k]) + half_dt2 * a[k]) + b3[k]) + b4[k]) + b5[k];
    v[k] := (v[k] + dt * a[k]) + (((THREE * b3[k]) + (FOUR * b4[k])) + (FIVE * b5[k])) / dt;
    a[k] := a[k] + two_over_dt2 * (((THREE * b3[k]) + (SIX * b4[k])) + (TEN * b5[k]));
    b3[k] := (b3[k] + FOUR * b4[k]) + TEN * b5[k];
    b4[k] := b4[k] + FIVE * b5[k];
  end;
end;

{ Ends with the rule for negligible derivatives (physics.md §3): a, b3, b4, b5 below the bound in
  magnitude become +0 (Abs(u) < bound is -bound < u < bound, as gear.hpp compares). }
procedure GearCorrector(n: LongInt; var x, v, a, b3, b4, b5: TDArr; const a_new: TDArr;
  cx, cv, c3, c4, c5, negligible: Double);
var k: LongInt; da: Double;
begin
  for k := 0 to 3 * n - 1 do
  begin
    da := a_new[k] - a[k];
    x[k] := x[k] + cx * da;
    v[k] := v[k] + cv * da;
    a[k] := a[k] + da;
    b3[k] := b3[k] + c3 * da;
    b4[k] := b4[k] + c4 * da;
    b5[k] := b5[k] + c5 * da;
    if Abs(a[k]) < negligible then a[k] := ZERO;
    if Abs(b3[k]) < negligible then b3[k] := ZERO;
    if Abs(b4[k]) < negligible then b4[k] := ZERO;
    if Abs(b5[k]) < negligible then b5[k] := ZERO;
  end;
end;

{ ---- contact law (contact_law.hpp) --------------------------------------------------------------- }

{ detail::contact_force }
procedure ContactForce(n0, n1, n2, h, u0, u1, u2, rstar, mstar, hertz: Double; const p: TProc;
  out fi0, fi1, fi2, ft0, ft1, ft2: Double);
var fn, un, ut0, ut1, ut2, ut_abs, ft, a1, a2: Double;
begin
  fn := ((hertz * Sqrt(rstar)) * h) * Sqrt(h);
  un := (u0 * n0 + u1 * n1) + u2 * n2;
  fn := fn + (p.gamma_n * mstar) * un;
  if fn < ZERO then fn := ZERO;
  ft0 := ZERO; ft1 := ZERO; ft2 := ZERO;
  ut0 := u0 - un * n0;
  ut1 := u1 - un * n1;
  ut2 := u2 - un * n2;
  ut_abs := Sqrt((ut0 * ut0 + ut1 * ut1) + ut2 * ut2);
  if ut_abs > ZERO then
  begin
    a1 := p.mu * fn;
    a2 := (p.gamma_t * mstar) * ut_abs;
    if a2 < a1 then ft := a2 else ft := a1;  { std::min(a1, a2) }
    ft0 := (-ft) * (ut0 / ut_abs);
    ft1 := (-ft) * (ut1 / ut_abs);
    ft2 := (-ft) * (ut2 / ut_abs);
  end;
  fi0 := (-fn) * n0 + ft0;
  fi1 := (-fn) * n1 + ft1;
  fi2 := (-fn) * n2 + ft2;
end;

{ particle_contact, i < j (0-based); adds forces and torques to p.f, p.t. False when h <= 0. }
function PairContact(var p: TProc; i, j: LongInt): Boolean;
var
  nn: LongInt;
  dx0, dx1, dx2, d, h, n0, n1, n2, rstar, mstar, s, ri, rj, mi, mj: Double;
  di0, di1, di2, dj0, dj1, dj2, u0, u1, u2, wi0, wi1, wi2, wj0, wj1, wj2: Double;
  fi0, fi1, fi2, ft0, ft1, ft2, mf0, mf1, mf2: Double;
begin
  nn := p.n;
  dx0 := p.x[j] - p.x[i];
  dx1 := p.x[nn + j] - p.x[nn + i];
  dx2 := p.x[2 * nn + j] - p.x[2 * nn + i];
  d := Sqrt((dx0 * dx0 + dx1 * dx1) + dx2 * dx2);
  ri := p.r[i]; rj := p.r[j]; mi := p.m[i]; mj := p.m[j];
  h := (ri + rj) - d;
  if not (h > ZERO) then Exit(False);
  Result := True;
  n0 := dx0 / d; n1 := dx1 / d; n2 := dx2 / d;
  rstar := (ri * rj) / (ri + rj);
  mstar := (mi * mj) / (mi + mj);
  s := ri - h * HALF;
  di0 := s * n0; di1 := s * n1; di2 := s * n2;
  s := rj - h * HALF;
  dj0 := -(s * n0); dj1 := -(s * n1); dj2 := -(s * n2);
  u0 := p.v[i] - p.v[j];
  u1 := p.v[nn + i] - p.v[nn + j];
  u2 := p.v[2 * nn + i] - p.v[2 * nn + j];
  wi0 := p.w[i]; wi1 := p.w[nn + i]; wi2 := p.w[2 * nn + i];
  wj0 := p.w[j]; wj1 := p.w[nn + j]; wj2 := p.w[2 * nn + j];
  { u = (u + cross(wi, di)) - cross(wj, dj) }
  u0 := (u0 + (wi1 * di2 - wi2 * di1)) - (wj1 * dj2 - wj2 * dj1);
  u1 := (u1 + (wi2 * di0 - wi0 * di2)) - (wj2 * dj0 - wj0 * dj2);
  u2 := (u2 + (wi0 * di1 - wi1 * di0)) - (wj0 * dj1 - wj1 * dj0);
  ContactForce(n0, n1, n2, h, u0, u1, u2, rstar, mstar, p.hertz_pp, p, fi0, fi1, fi2, ft0, ft1, ft2);
  p.f[i] := p.f[i] + fi0;
  p.f[nn + i] := p.f[nn + i] + fi1;
  p.f[2 * nn + i] := p.f[2 * nn + i] + fi2;
  p.f[j] := p.f[j] + (-fi0);
  p.f[nn + j] := p.f[nn + j] + (-fi1);
  p.f[2 * nn + j] := p.f[2 * nn + j] + (-fi2);
  { t_i = cross(di, ft); t_j = cross(dj, -ft) }
  p.t[i] := p.t[i] + (di1 * ft2 - di2 * ft1);
  p.t[nn + i] := p.t[nn + i] + (di2 * ft0 - di0 * ft2);
  p.t[2 * nn + i] := p.t[2 * nn + i] + (di0 * ft1 - di1 * ft0);
  mf0 := -ft0; mf1 := -ft1; mf2 := -ft2;
  p.t[j] := p.t[j] + (dj1 * mf2 - dj2 * mf1);
  p.t[nn + j] := p.t[nn + j] + (dj2 * mf0 - dj0 * mf2);
  p.t[2 * nn + j] := p.t[2 * nn + j] + (dj0 * mf1 - dj1 * mf0);
end;

{ wall_contact of particle i with wall iw (0-based). False when h <= 0. }
function WallContact(var p: TProc; i, iw: LongInt): Boolean;
var
  nn, b: LongInt;
  s, h, ri, sh, n0, n1, n2, di0, di1, di2, u0, u1, u2, wi0, wi1, wi2: Double;
  fi0, fi1, fi2, ft0, ft1, ft2: Double;
begin
  nn := p.n; b := 3 * iw;
  ri := p.r[i];
  s := ((p.x[i] - p.wp[b]) * p.wn[b] + (p.x[nn + i] - p.wp[b + 1]) * p.wn[b + 1])
       + (p.x[2 * nn + i] - p.wp[b + 2]) * p.wn[b + 2];
  h := ri - s;
  if not (h > ZERO) then Exit(False);
  Result := True;
  n0 := -p.wn[b]; n1 := -p.wn[b + 1]; n2 := -p.wn[b + 2];
  sh := ri - h * HALF;
  di0 := sh * n0; di1 := sh * n1; di2 := sh * n2;
  u0 := p.v[i] - p.wv[b];
  u1 := p.v[nn + i] - p.wv[b + 1];
  u2 := p.v[2 * nn + i] - p.wv[b + 2];
  wi0 := p.w[i]; wi1 := p.w[nn + i]; wi2 := p.w[2 * nn + i];
  u0 := u0 + (wi1 * di2 - wi2 * di1);
  u1 := u1 + (wi2 * di0 - wi0 * di2);
  u2 := u2 + (wi0 * di1 - wi1 * di0);
  ContactForce(n0, n1, n2, h, u0, u1, u2, ri, p.m[i], p.hertz_pw, p, fi0, fi1, fi2, ft0, ft1, ft2);
  p.f[i] := p.f[i] + fi0;
  p.f[nn + i] := p.f[nn + i] + fi1;
  p.f[2 * nn + i] := p.f[2 * nn + i] + fi2;
  p.t[i] := p.t[i] + (di1 * ft2 - di2 * ft1);
  p.t[nn + i] := p.t[nn + i] + (di2 * ft0 - di0 * ft2);
  p.t[2 * nn + i] := p.t[2 * nn + i] + (di0 * ft1 - di1 * ft0);
end;

{ ---- search -------------------------------------------------------------------------------------- }

{ may_touch: d2 < s*s*1.000000001 (the margin from C++) }
function MayTouch(const p: TProc; i, j: LongInt): Boolean; inline;
var nn: LongInt; dx0, dx1, dx2, d2, s: Double;
begin
  nn := p.n;
  dx0 := p.x[j] - p.x[i];
  dx1 := p.x[nn + j] - p.x[nn + i];
  dx2 := p.x[2 * nn + j] - p.x[2 * nn + i];
  d2 := (dx0 * dx0 + dx1 * dx1) + dx2 * dx2;
  s := p.r[i] + p.r[j];
  Result := d2 < (s * s) * p.margin;
end;

procedure InsertAscending(var row: TIArr; base, cnt, j: LongInt);
var k: LongInt;
begin
  k := cnt;
  while k > 0 do
  begin
    if row[base + k - 1] <= j then Break;
    row[base + k] := row[base + k - 1];
    Dec(k);
  end;
  row[base + k] := j;
end;

{ Partners j > i in ascending order; ST_PAIR_CAP with the worst particle on overflow. }
function SearchPairs(var p: TProc; out worst, worst_i: Int64): LongInt;
var
  n, i, j, c, k, ix, iy, iz, cnt: LongInt;
  hi, ti, ncell, s, ci: Int64;
  dims: array[0..2] of Int64;
  off: array[0..26] of Int64;
  lo, q, fq, d0, d1, d2, lim: Double;
  direct: Boolean;
begin
  n := p.n;
  worst := 0; worst_i := -1; Result := ST_OK;
  direct := False;
  if (p.cell > ZERO) and (n > 0) then
  begin
    for c := 0 to 2 do
    begin
      lo := p.x[c * n];
      for i := 1 to n - 1 do
        if p.x[c * n + i] < lo then lo := p.x[c * n + i];
      hi := 0;
      for i := 0 to n - 1 do
      begin
        q := (p.x[c * n + i] - lo) / p.cell;
        if not (Abs(q) < BIG) then
        begin
          worst_i := i;
          Exit(ST_RUNAWAY);
        end;
        ti := Trunc(q);   { floor }
        fq := ti;
        if fq > q then Dec(ti);
        p.cc3[c * n + i] := ti + 1;  { +1: an empty padding layer }
        if ti + 1 > hi then hi := ti + 1;
      end;
      dims[c] := hi + 2;
    end;
    d0 := dims[0]; d1 := dims[1]; d2 := dims[2];
    lim := 8 * Int64(n) + 4096;
    direct := (d0 * d1) * d2 <= lim;
    if direct then
    begin
      ncell := dims[0] * dims[1] * dims[2];
      if Length(p.head) < ncell then
      begin
        SetLength(p.head, 0);
        SetLength(p.head, ncell);
      end;
      for s := 0 to ncell - 1 do p.head[s] := -1;
      for i := n - 1 downto 0 do   { pushed in descending order: each cell's list ascends }
      begin
        s := p.cc3[i] + dims[0] * (p.cc3[n + i] + dims[1] * p.cc3[2 * n + i]);
        p.cellidx[i] := s;
        p.next[i] := p.head[s];
        p.head[s] := i;
      end;
      k := 0;
      for iz := -1 to 1 do
        for iy := -1 to 1 do
          for ix := -1 to 1 do
          begin
            off[k] := ix + dims[0] * (iy + dims[1] * iz);
            Inc(k);
          end;
    end;
  end;

  for i := 0 to n - 1 do
  begin
    cnt := 0;
    if direct then
    begin
      ci := p.cellidx[i];
      for k := 0 to 26 do
      begin
        j := p.head[ci + off[k]];
        while j >= 0 do
        begin
          if j > i then
            if MayTouch(p, i, j) then
            begin
              if cnt < p.cap then InsertAscending(p.partner, i * p.pcap, cnt, j);
              Inc(cnt);
            end;
          j := p.next[j];
        end;
      end;
    end
    else
      for j := i + 1 to n - 1 do
      begin
        if not MayTouch(p, i, j) then Continue;
        if cnt < p.cap then p.partner[i * p.pcap + cnt] := j;
        Inc(cnt);
      end;
    if cnt > worst then
    begin
      worst := cnt; worst_i := i;
    end;
    if p.cap < cnt then p.ncount[i] := p.cap else p.ncount[i] := cnt;
  end;
  if worst > p.cap then Result := ST_PAIR_CAP;
end;

function SearchWalls(var p: TProc; out bad_i: Int64): LongInt;
var iw, i, n, b: LongInt; s: Double;
begin
  Result := ST_OK; bad_i := -1;
  n := p.n;
  for i := 0 to n - 1 do p.wcount[i] := 0;
  for iw := 0 to p.nw - 1 do
  begin
    b := 3 * iw;
    for i := 0 to n - 1 do
    begin
      { may_touch_wall: dot(xi - point, normal) < ri*1.000000001 }
      s := ((p.x[i] - p.wp[b]) * p.wn[b] + (p.x[n + i] - p.wp[b + 1]) * p.wn[b + 1])
           + (p.x[2 * n + i] - p.wp[b + 2]) * p.wn[b + 2];
      if not (s < p.r[i] * p.margin) then Continue;
      if p.wcount[i] = p.wcap then
      begin
        bad_i := i;
        Exit(ST_WALL_CAP);
      end;
      p.wall[i * p.pwcap + p.wcount[i]] := iw;
      Inc(p.wcount[i]);
    end;
  end;
end;

{ ---- C entry points ------------------------------------------------------------------------------ }

function Valid(h: LongInt): Boolean; inline;
begin
  Result := (h >= 0) and (h < MAX_SLOTS) and Slots[h].used;
end;

procedure ClearSlot(h: LongInt);
begin
  Finalize(Slots[h]);
  FillChar(Slots[h], SizeOf(TProc), 0);
end;

{ A free slot index, or -1 when MAX_SLOTS instances are live. }
function demmat_pas_create: LongInt; cdecl;
var h: LongInt;
begin
  for h := 0 to MAX_SLOTS - 1 do
    if not Slots[h].used then
    begin
      ClearSlot(h);
      Slots[h].used := True;
      Exit(h);
    end;
  Result := -1;
end;

procedure demmat_pas_destroy(h: LongInt); cdecl;
begin
  if (h >= 0) and (h < MAX_SLOTS) then ClearSlot(h);
end;

function demmat_pas_max_instances: LongInt; cdecl;
begin
  Result := MAX_SLOTS;
end;

procedure CopyIn(var dst: TDArr; src: PDouble; count: SizeInt);
begin
  SetLength(dst, count);
  if count > 0 then Move(src^, dst[0], count * SizeOf(Double));
end;

{ gear: 12 arrays (x, v, a, b3, b4, b5, th, w, al, r3, r4, r5), each (N, 3) column-major.
  coef: dt, half_dt2, two_over_dt2, cx, cv, c3, c4, c5, the negligible-derivative bound (gear.hpp).
  contact: hertz_pp, hertz_pw, gamma_n, gamma_t, mu, may_touch margin (1.000000001). }
procedure demmat_pas_init(h, an, anw, acap, awcap: LongInt; acell: Double; radius, mass, inertia, gear, awn, awv,
  grav, coef, contact: PDouble); cdecl;
var saved: LongWord; n3: SizeInt; p: ^TProc;
begin
  if not Valid(h) then Exit;
  saved := EnterFP;
  p := @Slots[h];
  p^.n := an; p^.nw := anw; p^.cap := acap; p^.wcap := awcap; p^.cell := acell;
  if acap > 1 then p^.pcap := acap else p^.pcap := 1;
  if awcap > 1 then p^.pwcap := awcap else p^.pwcap := 1;
  p^.dt := coef[0]; p^.half_dt2 := coef[1]; p^.two_over_dt2 := coef[2];
  p^.cx := coef[3]; p^.cv := coef[4]; p^.c3 := coef[5]; p^.c4 := coef[6]; p^.c5 := coef[7];
  p^.negligible := coef[8];
  p^.hertz_pp := contact[0]; p^.hertz_pw := contact[1]; p^.gamma_n := contact[2]; p^.gamma_t := contact[3];
  p^.mu := contact[4]; p^.margin := contact[5];
  p^.g[0] := grav[0]; p^.g[1] := grav[1]; p^.g[2] := grav[2];
  n3 := 3 * SizeInt(an);
  CopyIn(p^.x, gear + 0 * n3, n3); CopyIn(p^.v, gear + 1 * n3, n3); CopyIn(p^.a, gear + 2 * n3, n3);
  CopyIn(p^.b3, gear + 3 * n3, n3); CopyIn(p^.b4, gear + 4 * n3, n3); CopyIn(p^.b5, gear + 5 * n3, n3);
  CopyIn(p^.th, gear + 6 * n3, n3); CopyIn(p^.w, gear + 7 * n3, n3); CopyIn(p^.al, gear + 8 * n3, n3);
  CopyIn(p^.r3, gear + 9 * n3, n3); CopyIn(p^.r4, gear + 10 * n3, n3); CopyIn(p^.r5, gear + 11 * n3, n3);
  SetLength(p^.f, n3); SetLength(p^.t, n3); SetLength(p^.acc, n3); SetLength(p^.alc, n3);  { zero-filled }
  CopyIn(p^.r, radius, an); CopyIn(p^.m, mass, an); CopyIn(p^.inert, inertia, an);
  SetLength(p^.wp, 3 * anw);
  CopyIn(p^.wn, awn, 3 * anw); CopyIn(p^.wv, awv, 3 * anw);
  SetLength(p^.ncount, an); SetLength(p^.partner, SizeInt(p^.pcap) * an);
  SetLength(p^.wcount, an); SetLength(p^.wall, SizeInt(p^.pwcap) * an);
  SetLength(p^.next, an); SetLength(p^.cellidx, an); SetLength(p^.cc3, n3);
  SetLength(p^.head, 0);
  LeaveFP(saved);
end;

procedure SetWalls(var p: TProc; wp: PDouble);
begin
  if p.nw > 0 then Move(wp^, p.wp[0], 3 * p.nw * SizeOf(Double));
end;

procedure demmat_pas_set_walls(h: LongInt; wp: PDouble); cdecl;
begin
  if Valid(h) then SetWalls(Slots[h], wp);
end;

procedure demmat_pas_predict(h: LongInt; wp: PDouble); cdecl;
var saved: LongWord;
begin
  if not Valid(h) then Exit;
  saved := EnterFP;
  with Slots[h] do
  begin
    GearPredictor(n, x, v, a, b3, b4, b5, dt, half_dt2, two_over_dt2);
    GearPredictor(n, th, w, al, r3, r4, r5, dt, half_dt2, two_over_dt2);
  end;
  SetWalls(Slots[h], wp);
  LeaveFP(saved);
end;

{ status: 0 ok; 1 pair capacity (info = worst count, particle); 2 wall capacity (particle);
  3 runaway position (particle). Particles 0-based. }
procedure demmat_pas_search(h: LongInt; status: PLongInt; info, particle: PInt64); cdecl;
var saved: LongWord; st: LongInt; worst, wi: Int64;
begin
  if not Valid(h) then Exit;
  saved := EnterFP;
  st := SearchPairs(Slots[h], worst, wi);
  if st = ST_OK then st := SearchWalls(Slots[h], wi);
  status^ := st; info^ := worst; particle^ := wi;
  LeaveFP(saved);
end;

procedure demmat_pas_forces(h: LongInt); cdecl;
var saved: LongWord; i, k, c: LongInt;
begin
  if not Valid(h) then Exit;
  saved := EnterFP;
  with Slots[h] do
  begin
    for k := 0 to 3 * n - 1 do
    begin
      f[k] := ZERO; t[k] := ZERO;
    end;
    pp := 0; pw := 0; cand := 0;
    for i := 0 to n - 1 do
    begin
      cand := cand + ncount[i];
      for k := 0 to ncount[i] - 1 do
        if PairContact(Slots[h], i, partner[i * pcap + k]) then Inc(pp);
    end;
    for i := 0 to n - 1 do
      for k := 0 to wcount[i] - 1 do
        if WallContact(Slots[h], i, wall[i * pwcap + k]) then Inc(pw);
    for c := 0 to 2 do
      for i := 0 to n - 1 do
      begin
        acc[c * n + i] := f[c * n + i] / m[i] + g[c];
        alc[c * n + i] := t[c * n + i] / inert[i];
      end;
  end;
  LeaveFP(saved);
end;

procedure demmat_pas_correct(h: LongInt); cdecl;
var saved: LongWord;
begin
  if not Valid(h) then Exit;
  saved := EnterFP;
  with Slots[h] do
  begin
    GearCorrector(n, x, v, a, b3, b4, b5, acc, cx, cv, c3, c4, c5, negligible);
    GearCorrector(n, th, w, al, r3, r4, r5, alc, cx, cv, c3, c4, c5, negligible);
  end;
  LeaveFP(saved);
end;

{ which: 1..12 the Gear arrays (x, v, a, b3, b4, b5, th, w, al, r3, r4, r5), 13 force, 14 torque. }
procedure demmat_pas_get(h, which: LongInt; out_: PDouble); cdecl;
var src: TDArr;
begin
  if not Valid(h) then Exit;
  with Slots[h] do
  begin
    case which of
      1: src := x; 2: src := v; 3: src := a; 4: src := b3; 5: src := b4; 6: src := b5;
      7: src := th; 8: src := w; 9: src := al; 10: src := r3; 11: src := r4; 12: src := r5;
      13: src := f; 14: src := t;
    else
      Exit;
    end;
    if Length(src) > 0 then Move(src[0], out_^, Length(src) * SizeOf(Double));
  end;
end;

{ counts: pp, pw, candidates; bytes held. }
procedure demmat_pas_counts(h: LongInt; out_: PInt64); cdecl;
var b: Int64;
begin
  if not Valid(h) then Exit;
  with Slots[h] do
  begin
    out_[0] := pp; out_[1] := pw; out_[2] := cand;
    b := 19 * 3 * Int64(n) * 8;
    b := b + 4 * (Int64(Length(partner)) + Length(ncount) + Length(wall) + Length(wcount));
    b := b + 4 * Int64(Length(next)) + 8 * (Int64(Length(cellidx)) + Length(cc3));
    b := b + 4 * Int64(Length(head));
    out_[3] := b;
  end;
end;

exports
  demmat_pas_create name 'demmat_pas_create',
  demmat_pas_destroy name 'demmat_pas_destroy',
  demmat_pas_max_instances name 'demmat_pas_max_instances',
  demmat_pas_init name 'demmat_pas_init',
  demmat_pas_set_walls name 'demmat_pas_set_walls',
  demmat_pas_predict name 'demmat_pas_predict',
  demmat_pas_search name 'demmat_pas_search',
  demmat_pas_forces name 'demmat_pas_forces',
  demmat_pas_correct name 'demmat_pas_correct',
  demmat_pas_get name 'demmat_pas_get',
  demmat_pas_counts name 'demmat_pas_counts';

begin
  { the RTL's start-up may unmask FP exceptions; give the host back the C default environment }
  SetMXCSR($1F80);
  Set8087CW($037F);
end.
