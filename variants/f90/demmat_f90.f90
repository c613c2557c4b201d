! DEMMAT_F90: the arrays processor (variants/arrays) in Fortran 90, driven from C++ through bind(C).
!
! The particles' state is held in allocatable real(8) arrays of shape (N, 3) (rows = particles,
! columns = components), passed as explicit-shape dummy arguments with intent attributes to the
! EXTERNAL procedures gear_predictor, gear_corrector, contact_force, pair_contact and wall_contact
! (and their helpers dot, cross), defined after `end module demmat_f90` and declared once by the
! INTERFACE block of module demmat_f90_kernels (the paper's style); they use no module data. Capacities are
! fixed at init; an overflow is reported to C++ as a status code (C++ throws CapacityError /
! InstabilityError with the messages of the arrays variant). Every expression mirrors
! common/include/demmat/{gear,contact_law}.hpp operation for operation; the parentheses spell
! out C++'s left-to-right evaluation (Fortran honours parentheses), so the trajectories are
! bit-identical to the C++ variants (physics.md section 6). Constants (Gear coefficients, contact
! parameters) are passed in from C++, never recomputed here.
!
! Search: linked cells (head/next) over the particles' bounding box, padded by one empty cell layer,
! as a direct grid of dims(1)*dims(2)*dims(3) cells. When that grid would exceed 8*N + 4096 cells (a
! huge, sparse box) the search falls back to the all-pairs loop; the candidate set is the same either
! way (may_touch decides). cell_size == 0 means all pairs.

! Explicit interfaces of the external compute kernels (defined after module demmat_f90), written once
! and used by the module and by the kernels that call each other.
module demmat_f90_kernels
  implicit none
  interface
    subroutine gear_predictor(n, x, v, a, b3, b4, b5, dt, half_dt2, two_over_dt2)
      use, intrinsic :: iso_c_binding
      implicit none
      integer, parameter :: dp = c_double
      integer, intent(in) :: n
      real(dp), intent(inout) :: x(n, 3), v(n, 3), a(n, 3), b3(n, 3), b4(n, 3)
      real(dp), intent(in) :: b5(n, 3)
      real(dp), intent(in) :: dt, half_dt2, two_over_dt2
    end subroutine gear_predictor
    subroutine gear_corrector(n, x, v, a, b3, b4, b5, a_new, cx, cv, c3, c4, c5, negligible)
      use, intrinsic :: iso_c_binding
      implicit none
      integer, parameter :: dp = c_double
      integer, intent(in) :: n
      real(dp), intent(inout) :: x(n, 3), v(n, 3), a(n, 3), b3(n, 3), b4(n, 3), b5(n, 3)
      real(dp), intent(in) :: a_new(n, 3)
      real(dp), intent(in) :: cx, cv, c3, c4, c5, negligible
    end subroutine gear_corrector
    pure function cross(a, b) result(c)
      use, intrinsic :: iso_c_binding
      implicit none
      integer, parameter :: dp = c_double
      real(dp), intent(in) :: a(3), b(3)
      real(dp) :: c(3)
    end function cross
    pure function dot(a, b) result(s)
      use, intrinsic :: iso_c_binding
      implicit none
      integer, parameter :: dp = c_double
      real(dp), intent(in) :: a(3), b(3)
      real(dp) :: s
    end function dot
    subroutine contact_force(n, h, u, rstar, mstar, hertz, gamma_n, gamma_t, mu, f_i, f_t)
      use, intrinsic :: iso_c_binding
      implicit none
      integer, parameter :: dp = c_double
      real(dp), intent(in) :: n(3), h, u(3), rstar, mstar, hertz, gamma_n, gamma_t, mu
      real(dp), intent(out) :: f_i(3), f_t(3)
    end subroutine contact_force
    logical function pair_contact(nn, i, j, x, v, w, r, m, f, t, hertz, gamma_n, gamma_t, mu)
      use, intrinsic :: iso_c_binding
      implicit none
      integer, parameter :: dp = c_double
      integer, intent(in) :: nn, i, j
      real(dp), intent(in) :: x(nn, 3), v(nn, 3), w(nn, 3), r(nn), m(nn)
      real(dp), intent(inout) :: f(nn, 3), t(nn, 3)
      real(dp), intent(in) :: hertz, gamma_n, gamma_t, mu
    end function pair_contact
    logical function wall_contact(nn, i, x, v, w, r, m, f, t, point, normal, vw, hertz, gamma_n, gamma_t, mu)
      use, intrinsic :: iso_c_binding
      implicit none
      integer, parameter :: dp = c_double
      integer, intent(in) :: nn, i
      real(dp), intent(in) :: x(nn, 3), v(nn, 3), w(nn, 3), r(nn), m(nn)
      real(dp), intent(inout) :: f(nn, 3), t(nn, 3)
      real(dp), intent(in) :: point(3), normal(3), vw(3), hertz, gamma_n, gamma_t, mu
    end function wall_contact
  end interface
end module demmat_f90_kernels

module demmat_f90
  use, intrinsic :: iso_c_binding
  use demmat_f90_kernels  ! the external compute kernels' interfaces (defined after `end module`)
  implicit none
  private

  integer, parameter :: dp = c_double
  integer, parameter :: i8 = c_int64_t

  ! status codes returned to C++
  integer(c_int), parameter :: ST_OK = 0, ST_PAIR_CAP = 1, ST_WALL_CAP = 2, ST_RUNAWAY = 3

  type :: processor
    integer :: n = 0, nw = 0, cap = 0, wcap = 0
    real(dp) :: cell = 0.0_dp
    ! Gear coefficients and contact parameters (from C++)
    real(dp) :: dt, half_dt2, two_over_dt2, cx, cv, c3, c4, c5, negligible
    real(dp) :: hertz_pp, hertz_pw, gamma_n, gamma_t, mu, margin
    real(dp) :: g(3)
    ! state, (N, 3) each
    real(dp), allocatable :: x(:,:), v(:,:), a(:,:), b3(:,:), b4(:,:), b5(:,:)
    real(dp), allocatable :: th(:,:), w(:,:), al(:,:), r3(:,:), r4(:,:), r5(:,:)
    real(dp), allocatable :: f(:,:), t(:,:), acc(:,:), alc(:,:)
    real(dp), allocatable :: r(:), m(:), inert(:)
    ! walls, (3, nw)
    real(dp), allocatable :: wp(:,:), wn(:,:), wv(:,:)
    ! contact store
    integer, allocatable :: ncount(:), partner(:,:)   ! (N), (cap, N)
    integer, allocatable :: wcount(:), wall(:,:)      ! (N), (wcap, N)
    ! linked cells
    integer, allocatable :: head(:), next(:)
    integer(i8), allocatable :: cellidx(:), cc3(:,:)
    integer(i8) :: pp = 0, pw = 0, cand = 0
  end type processor


  public :: f90_create, f90_destroy, f90_init, f90_predict, f90_search, f90_forces, f90_correct
  public :: f90_get, f90_counts

contains

  ! ---- search ------------------------------------------------------------------------------------

  subroutine insert_ascending(row, cnt, j)
    integer, intent(inout) :: row(:)
    integer, intent(in) :: cnt, j
    integer :: k
    k = cnt
    do while (k > 0)
      if (row(k) <= j) exit
      row(k + 1) = row(k)
      k = k - 1
    end do
    row(k + 1) = j
  end subroutine insert_ascending

  ! may_touch on scalars (contact_law.hpp): d2 < s*s*margin, the margin from C++ (kMayTouchMargin).
  pure logical function may_touch_s(xi1, xi2, xi3, xj1, xj2, xj3, ri, rj, margin)
    real(dp), intent(in) :: xi1, xi2, xi3, xj1, xj2, xj3, ri, rj, margin
    real(dp) :: dx1, dx2, dx3, d2, s
    dx1 = xj1 - xi1
    dx2 = xj2 - xi2
    dx3 = xj3 - xi3
    d2 = (dx1*dx1 + dx2*dx2) + dx3*dx3
    s = ri + rj
    may_touch_s = d2 < (s*s)*margin
  end function may_touch_s

  subroutine scan_cells(n, x, r, margin, cap, head, next, cellidx, off, ncount, partner, worst, worst_i)
    integer, intent(in) :: n, cap
    real(dp), intent(in) :: x(n, 3), r(n), margin
    integer, intent(in) :: head(0:), next(n)
    integer(i8), intent(in) :: cellidx(n), off(27)
    integer, intent(out) :: ncount(n)
    integer, intent(inout) :: partner(:, :)
    integer(i8), intent(inout) :: worst, worst_i
    integer :: i, j, k, c
    real(dp) :: xi1, xi2, xi3, ri
    do i = 1, n
      c = 0
      xi1 = x(i, 1); xi2 = x(i, 2); xi3 = x(i, 3); ri = r(i)
      do k = 1, 27
        j = head(cellidx(i) + off(k))
        do while (j > 0)
          if (j > i) then
            if (may_touch_s(xi1, xi2, xi3, x(j, 1), x(j, 2), x(j, 3), ri, r(j), margin)) then
              if (c < cap) call insert_ascending(partner(:, i), c, j)
              c = c + 1
            end if
          end if
          j = next(j)
        end do
      end do
      if (c > worst) then
        worst = c; worst_i = i - 1
      end if
      ncount(i) = min(c, cap)
    end do
  end subroutine scan_cells

  subroutine scan_all_pairs(n, x, r, margin, cap, ncount, partner, worst, worst_i)
    integer, intent(in) :: n, cap
    real(dp), intent(in) :: x(n, 3), r(n), margin
    integer, intent(out) :: ncount(n)
    integer, intent(inout) :: partner(:, :)
    integer(i8), intent(inout) :: worst, worst_i
    integer :: i, j, c
    do i = 1, n
      c = 0
      do j = i + 1, n
        if (.not. may_touch_s(x(i, 1), x(i, 2), x(i, 3), x(j, 1), x(j, 2), x(j, 3), r(i), r(j), margin)) cycle
        if (c < cap) partner(c + 1, i) = j
        c = c + 1
      end do
      if (c > worst) then
        worst = c; worst_i = i - 1
      end if
      ncount(i) = min(c, cap)
    end do
  end subroutine scan_all_pairs

  ! Partners j > i (1-based) in ascending order; status ST_PAIR_CAP with the worst particle on overflow.
  subroutine search_pairs(p, status, worst, worst_i)
    type(processor), intent(inout) :: p
    integer(c_int), intent(out) :: status
    integer(i8), intent(out) :: worst, worst_i
    integer :: i, c, k, n, ix, iy, iz
    integer(i8) :: hi, dims(3), ncell, s, off(27)
    real(dp) :: lo, fq, q
    logical :: direct
    n = p%n
    worst = 0; worst_i = -1; status = ST_OK
    direct = .false.
    if (p%cell > 0.0_dp .and. n > 0) then
      ! bin into cells of edge p%cell over the bounding box, one empty padding layer on each side
      do c = 1, 3
        lo = minval(p%x(:, c))
        hi = 0
        do i = 1, n
          q = (p%x(i, c) - lo)/p%cell
          fq = aint(q)
          if (fq > q) fq = fq - 1.0_dp   ! floor
          if (.not. (abs(fq) < 1099511627776.0_dp)) then
            status = ST_RUNAWAY; worst_i = i - 1
            return
          end if
          p%cc3(i, c) = int(fq, i8) + 1    ! +1: an empty padding layer
          hi = max(hi, p%cc3(i, c))
        end do
        dims(c) = hi + 2
      end do
      direct = real(dims(1), dp)*real(dims(2), dp)*real(dims(3), dp) <= real(8*int(n, i8) + 4096, dp)
      if (direct) then
        ncell = dims(1)*dims(2)*dims(3)
        if (allocated(p%head)) then
          if (size(p%head, kind=i8) < ncell) deallocate(p%head)
        end if
        if (.not. allocated(p%head)) allocate(p%head(0:ncell - 1))
        p%head(0:ncell - 1) = 0
        do i = n, 1, -1   ! pushed in descending order: each cell's list ascends
          s = p%cc3(i, 1) + dims(1)*(p%cc3(i, 2) + dims(2)*p%cc3(i, 3))
          p%cellidx(i) = s
          p%next(i) = p%head(s)
          p%head(s) = i
        end do
        k = 0
        do iz = -1, 1
          do iy = -1, 1
            do ix = -1, 1
              k = k + 1
              off(k) = ix + dims(1)*(iy + dims(2)*iz)
            end do
          end do
        end do
      end if
    end if

    if (direct) then
      call scan_cells(n, p%x, p%r, p%margin, p%cap, p%head, p%next, p%cellidx, off, p%ncount, p%partner, worst, worst_i)
    else
      call scan_all_pairs(n, p%x, p%r, p%margin, p%cap, p%ncount, p%partner, worst, worst_i)
    end if
    if (worst > p%cap) status = ST_PAIR_CAP
  end subroutine search_pairs

  subroutine search_walls(p, status, bad_i)
    type(processor), intent(inout) :: p
    integer(c_int), intent(out) :: status
    integer(i8), intent(out) :: bad_i
    integer :: iw, i
    status = ST_OK; bad_i = -1
    p%wcount = 0
    do iw = 1, p%nw
      do i = 1, p%n
        if (.not. (dot(p%x(i, :) - p%wp(:, iw), p%wn(:, iw)) < p%r(i)*p%margin)) cycle
        if (p%wcount(i) == p%wcap) then
          status = ST_WALL_CAP; bad_i = i - 1
          return
        end if
        p%wcount(i) = p%wcount(i) + 1
        p%wall(p%wcount(i), i) = iw
      end do
    end do
  end subroutine search_walls

  ! ---- C entry points ----------------------------------------------------------------------------

  function get(h) result(p)
    type(c_ptr), intent(in) :: h
    type(processor), pointer :: p
    call c_f_pointer(h, p)
  end function get

  function f90_create() result(h) bind(C, name="demmat_f90_create")
    type(c_ptr) :: h
    type(processor), pointer :: p
    allocate(p)
    h = c_loc(p)
  end function f90_create

  subroutine f90_destroy(h) bind(C, name="demmat_f90_destroy")
    type(c_ptr), value :: h
    type(processor), pointer :: p
    p => get(h)
    deallocate(p)   ! frees the allocatable components too
  end subroutine f90_destroy

  ! gear: 12 arrays (x, v, a, b3, b4, b5, th, w, al, r3, r4, r5), each (N, 3) column-major, in `gear`.
  ! coef: dt, half_dt2, two_over_dt2, cx, cv, c3, c4, c5, the negligible-derivative bound (gear.hpp); contact: hertz_pp, hertz_pw, gamma_n, gamma_t, mu, may_touch margin.
  subroutine f90_init(h, n, nw, cap, wcap, cell, radius, mass, inertia, gear, wn, wv, grav, coef, contact) &
      bind(C, name="demmat_f90_init")
    type(c_ptr), value :: h
    integer(c_int), value :: n, nw, cap, wcap
    real(c_double), value :: cell
    real(c_double), intent(in) :: radius(n), mass(n), inertia(n), gear(n, 3, 12), wn(3, nw), wv(3, nw)
    real(c_double), intent(in) :: grav(3), coef(9), contact(6)
    type(processor), pointer :: p
    p => get(h)
    p%n = n; p%nw = nw; p%cap = cap; p%wcap = wcap; p%cell = cell
    p%dt = coef(1); p%half_dt2 = coef(2); p%two_over_dt2 = coef(3)
    p%cx = coef(4); p%cv = coef(5); p%c3 = coef(6); p%c4 = coef(7); p%c5 = coef(8)
    p%negligible = coef(9)
    p%hertz_pp = contact(1); p%hertz_pw = contact(2); p%gamma_n = contact(3); p%gamma_t = contact(4); p%mu = contact(5)
    p%margin = contact(6)
    p%g = grav
    p%x = gear(:, :, 1); p%v = gear(:, :, 2); p%a = gear(:, :, 3)
    p%b3 = gear(:, :, 4); p%b4 = gear(:, :, 5); p%b5 = gear(:, :, 6)
    p%th = gear(:, :, 7); p%w = gear(:, :, 8); p%al = gear(:, :, 9)
    p%r3 = gear(:, :, 10); p%r4 = gear(:, :, 11); p%r5 = gear(:, :, 12)
    allocate(p%f(n, 3), p%t(n, 3), p%acc(n, 3), p%alc(n, 3))
    p%f = 0.0_dp; p%t = 0.0_dp; p%acc = 0.0_dp; p%alc = 0.0_dp
    p%r = radius; p%m = mass; p%inert = inertia
    allocate(p%wp(3, nw))
    p%wp = 0.0_dp
    p%wn = wn; p%wv = wv
    allocate(p%ncount(n), p%partner(max(cap, 1), n), p%wcount(n), p%wall(max(wcap, 1), n))
    p%ncount = 0; p%partner = 0; p%wcount = 0; p%wall = 0
    allocate(p%next(n), p%cellidx(n), p%cc3(n, 3))
    p%next = 0; p%cellidx = 0
  end subroutine f90_init

  subroutine f90_predict(h, wp) bind(C, name="demmat_f90_predict")
    type(c_ptr), value :: h
    type(processor), pointer :: p
    real(c_double), intent(in) :: wp(*)
    p => get(h)
    call gear_predictor(p%n, p%x, p%v, p%a, p%b3, p%b4, p%b5, p%dt, p%half_dt2, p%two_over_dt2)
    call gear_predictor(p%n, p%th, p%w, p%al, p%r3, p%r4, p%r5, p%dt, p%half_dt2, p%two_over_dt2)
    call set_walls(p, wp)
  end subroutine f90_predict

  subroutine set_walls(p, wp)
    type(processor), intent(inout) :: p
    real(c_double), intent(in) :: wp(3, *)
    if (p%nw > 0) p%wp = wp(:, 1:p%nw)
  end subroutine set_walls

  subroutine f90_set_walls(h, wp) bind(C, name="demmat_f90_set_walls")
    type(c_ptr), value :: h
    real(c_double), intent(in) :: wp(*)
    type(processor), pointer :: p
    p => get(h)
    call set_walls(p, wp)
  end subroutine f90_set_walls

  ! status: 0 ok; 1 pair capacity (info = worst count, particle); 2 wall capacity (particle);
  ! 3 runaway position (particle). Particles 0-based.
  subroutine f90_search(h, status, info, particle) bind(C, name="demmat_f90_search")
    type(c_ptr), value :: h
    integer(c_int), intent(out) :: status
    integer(c_int64_t), intent(out) :: info, particle
    type(processor), pointer :: p
    p => get(h)
    call search_pairs(p, status, info, particle)
    if (status /= ST_OK) return
    call search_walls(p, status, particle)
  end subroutine f90_search

  subroutine f90_forces(h) bind(C, name="demmat_f90_forces")
    type(c_ptr), value :: h
    type(processor), pointer :: p
    integer :: i, k, c
    p => get(h)
    p%f = 0.0_dp
    p%t = 0.0_dp
    p%pp = 0; p%pw = 0; p%cand = 0
    do i = 1, p%n
      p%cand = p%cand + p%ncount(i)
      do k = 1, p%ncount(i)
        if (pair_contact(p%n, i, p%partner(k, i), p%x, p%v, p%w, p%r, p%m, p%f, p%t, &
                         p%hertz_pp, p%gamma_n, p%gamma_t, p%mu)) p%pp = p%pp + 1
      end do
    end do
    do i = 1, p%n
      do k = 1, p%wcount(i)
        c = p%wall(k, i)
        if (wall_contact(p%n, i, p%x, p%v, p%w, p%r, p%m, p%f, p%t, p%wp(:, c), p%wn(:, c), p%wv(:, c), &
                         p%hertz_pw, p%gamma_n, p%gamma_t, p%mu)) p%pw = p%pw + 1
      end do
    end do
    do c = 1, 3
      do i = 1, p%n
        p%acc(i, c) = p%f(i, c)/p%m(i) + p%g(c)
        p%alc(i, c) = p%t(i, c)/p%inert(i)
      end do
    end do
  end subroutine f90_forces

  subroutine f90_correct(h) bind(C, name="demmat_f90_correct")
    type(c_ptr), value :: h
    type(processor), pointer :: p
    p => get(h)
    call gear_corrector(p%n, p%x, p%v, p%a, p%b3, p%b4, p%b5, p%acc, p%cx, p%cv, p%c3, p%c4, p%c5, p%negligible)
    call gear_corrector(p%n, p%th, p%w, p%al, p%r3, p%r4, p%r5, p%alc, p%cx, p%cv, p%c3, p%c4, p%c5, p%negligible)
  end subroutine f90_correct

  ! which: 1..12 the Gear arrays (x, v, a, b3, b4, b5, th, w, al, r3, r4, r5), 13 force, 14 torque.
  subroutine f90_get(h, which, out) bind(C, name="demmat_f90_get")
    type(c_ptr), value :: h
    integer(c_int), value :: which
    type(processor), pointer :: p
    real(c_double), intent(out) :: out(*)
    p => get(h)
    call copy_out(p%n, which, p, out)
  end subroutine f90_get

  subroutine copy_out(n, which, p, out)
    integer, intent(in) :: n
    integer(c_int), intent(in) :: which
    type(processor), intent(in) :: p
    real(c_double), intent(out) :: out(n, 3)
    select case (which)
    case (1); out = p%x
    case (2); out = p%v
    case (3); out = p%a
    case (4); out = p%b3
    case (5); out = p%b4
    case (6); out = p%b5
    case (7); out = p%th
    case (8); out = p%w
    case (9); out = p%al
    case (10); out = p%r3
    case (11); out = p%r4
    case (12); out = p%r5
    case (13); out = p%f
    case (14); out = p%t
    end select
  end subroutine copy_out

  ! counts: pp, pw, candidates; bytes held.
  subroutine f90_counts(h, out) bind(C, name="demmat_f90_counts")
    type(c_ptr), value :: h
    integer(c_int64_t), intent(out) :: out(4)
    type(processor), pointer :: p
    integer(i8) :: b
    p => get(h)
    out(1) = p%pp; out(2) = p%pw; out(3) = p%cand
    b = 19_i8*3_i8*int(p%n, i8)*8_i8
    b = b + 4_i8*(size(p%partner, kind=i8) + size(p%ncount, kind=i8) + size(p%wall, kind=i8) + size(p%wcount, kind=i8))
    b = b + 4_i8*size(p%next, kind=i8) + 8_i8*(size(p%cellidx, kind=i8) + size(p%cc3, kind=i8))
    if (allocated(p%head)) b = b + 4_i8*size(p%head, kind=i8)
    out(4) = b
  end subroutine f90_counts

end module demmat_f90

! ==== external compute kernels (explicit interfaces: the interface block in module demmat_f90) ====

! ---- Gear --------------------------------------------------------------------------------------

subroutine gear_predictor(n, x, v, a, b3, b4, b5, dt, half_dt2, two_over_dt2)
  use, intrinsic :: iso_c_binding
  implicit none
  integer, parameter :: dp = c_double
  integer, intent(in) :: n
  real(dp), intent(inout) :: x(n, 3), v(n, 3), a(n, 3), b3(n, 3), b4(n, 3)
  real(dp), intent(in) :: b5(n, 3)
  real(dp), intent(in) :: dt, half_dt2, two_over_dt2
  integer :: i, c
  do c = 1, 3
    do i = 1, n
      x(i, c) = ((((x(i, c) + dt*v(i, c)) + half_dt2*a(i, c)) + b3(i, c)) + b4(i, c)) + b5(i, c)
      v(i, c) = (v(i, c) + dt*a(i, c)) + (((3.0_dp*b3(i, c)) + (4.0_dp*b4(i, c))) + (5.0_dp*b5(i, c)))/dt
      a(i, c) = a(i, c) + two_over_dt2*(((3.0_dp*b3(i, c)) + (6.0_dp*b4(i, c))) + (10.0_dp*b5(i, c)))
      b3(i, c) = (b3(i, c) + 4.0_dp*b4(i, c)) + 10.0_dp*b5(i, c)
      b4(i, c) = b4(i, c) + 5.0_dp*b5(i, c)
    end do
  end do
end subroutine gear_predictor

! Ends with the rule for negligible derivatives (physics.md §3): a, b3, b4, b5 below the bound in
! magnitude become +0 (abs(u) < bound is -bound < u < bound, as gear.hpp compares).
subroutine gear_corrector(n, x, v, a, b3, b4, b5, a_new, cx, cv, c3, c4, c5, negligible)
  use, intrinsic :: iso_c_binding
  implicit none
  integer, parameter :: dp = c_double
  integer, intent(in) :: n
  real(dp), intent(inout) :: x(n, 3), v(n, 3), a(n, 3), b3(n, 3), b4(n, 3), b5(n, 3)
  real(dp), intent(in) :: a_new(n, 3)
  real(dp), intent(in) :: cx, cv, c3, c4, c5, negligible
  integer :: i, c
  real(dp) :: da
  do c = 1, 3
    do i = 1, n
      da = a_new(i, c) - a(i, c)
      x(i, c) = x(i, c) + cx*da
      v(i, c) = v(i, c) + cv*da
      a(i, c) = a(i, c) + da
      b3(i, c) = b3(i, c) + c3*da
      b4(i, c) = b4(i, c) + c4*da
      b5(i, c) = b5(i, c) + c5*da
      if (abs(a(i, c)) < negligible) a(i, c) = 0.0_dp
      if (abs(b3(i, c)) < negligible) b3(i, c) = 0.0_dp
      if (abs(b4(i, c)) < negligible) b4(i, c) = 0.0_dp
      if (abs(b5(i, c)) < negligible) b5(i, c) = 0.0_dp
    end do
  end do
end subroutine gear_corrector

! ---- contact law (contact_law.hpp) -------------------------------------------------------------

pure function cross(a, b) result(c)
  use, intrinsic :: iso_c_binding
  implicit none
  integer, parameter :: dp = c_double
  real(dp), intent(in) :: a(3), b(3)
  real(dp) :: c(3)
  c(1) = a(2)*b(3) - a(3)*b(2)
  c(2) = a(3)*b(1) - a(1)*b(3)
  c(3) = a(1)*b(2) - a(2)*b(1)
end function cross

pure function dot(a, b) result(s)
  use, intrinsic :: iso_c_binding
  implicit none
  integer, parameter :: dp = c_double
  real(dp), intent(in) :: a(3), b(3)
  real(dp) :: s
  s = (a(1)*b(1) + a(2)*b(2)) + a(3)*b(3)
end function dot

! detail::contact_force
subroutine contact_force(n, h, u, rstar, mstar, hertz, gamma_n, gamma_t, mu, f_i, f_t)
  use, intrinsic :: iso_c_binding
  use demmat_f90_kernels, only: dot
  implicit none
  integer, parameter :: dp = c_double
  real(dp), intent(in) :: n(3), h, u(3), rstar, mstar, hertz, gamma_n, gamma_t, mu
  real(dp), intent(out) :: f_i(3), f_t(3)
  real(dp) :: fn, un, ut(3), ut_abs, ft, a1, a2
  fn = ((hertz*sqrt(rstar))*h)*sqrt(h)
  un = dot(u, n)
  fn = fn + (gamma_n*mstar)*un
  if (fn < 0.0_dp) fn = 0.0_dp
  f_t = 0.0_dp
  ut = u - un*n
  ut_abs = sqrt(dot(ut, ut))
  if (ut_abs > 0.0_dp) then
    a1 = mu*fn
    a2 = (gamma_t*mstar)*ut_abs
    ft = a1                    ! std::min(a1, a2): a2 < a1 ? a2 : a1
    if (a2 < a1) ft = a2
    f_t = (-ft)*(ut/ut_abs)
  end if
  f_i = (-fn)*n + f_t
end subroutine contact_force

! particle_contact, i < j; adds the forces and torques to f and t (N, 3). Returns .false. when h <= 0.
logical function pair_contact(nn, i, j, x, v, w, r, m, f, t, hertz, gamma_n, gamma_t, mu)
  use, intrinsic :: iso_c_binding
  use demmat_f90_kernels, only: cross, dot, contact_force
  implicit none
  integer, parameter :: dp = c_double
  integer, intent(in) :: nn, i, j
  real(dp), intent(in) :: x(nn, 3), v(nn, 3), w(nn, 3), r(nn), m(nn)
  real(dp), intent(inout) :: f(nn, 3), t(nn, 3)
  real(dp), intent(in) :: hertz, gamma_n, gamma_t, mu
  real(dp) :: dx(3), d, h, n(3), rstar, mstar, di(3), dj(3), u(3), f_i(3), f_t(3), ri, rj, mi, mj
  dx = x(j, :) - x(i, :)
  d = sqrt(dot(dx, dx))
  ri = r(i); rj = r(j); mi = m(i); mj = m(j)
  h = (ri + rj) - d
  pair_contact = .false.
  if (.not. (h > 0.0_dp)) return
  pair_contact = .true.
  n = dx/d
  rstar = (ri*rj)/(ri + rj)
  mstar = (mi*mj)/(mi + mj)
  di = (ri - h*0.5_dp)*n
  dj = -((rj - h*0.5_dp)*n)
  u = v(i, :) - v(j, :)
  u = (u + cross(w(i, :), di)) - cross(w(j, :), dj)
  call contact_force(n, h, u, rstar, mstar, hertz, gamma_n, gamma_t, mu, f_i, f_t)
  f(i, :) = f(i, :) + f_i
  f(j, :) = f(j, :) + (-f_i)
  t(i, :) = t(i, :) + cross(di, f_t)
  t(j, :) = t(j, :) + cross(dj, -f_t)
end function pair_contact

! wall_contact; adds to particle i. Returns .false. when h <= 0.
logical function wall_contact(nn, i, x, v, w, r, m, f, t, point, normal, vw, hertz, gamma_n, gamma_t, mu)
  use, intrinsic :: iso_c_binding
  use demmat_f90_kernels, only: cross, dot, contact_force
  implicit none
  integer, parameter :: dp = c_double
  integer, intent(in) :: nn, i
  real(dp), intent(in) :: x(nn, 3), v(nn, 3), w(nn, 3), r(nn), m(nn)
  real(dp), intent(inout) :: f(nn, 3), t(nn, 3)
  real(dp), intent(in) :: point(3), normal(3), vw(3), hertz, gamma_n, gamma_t, mu
  real(dp) :: s, h, n(3), di(3), u(3), f_i(3), f_t(3), ri
  ri = r(i)
  s = dot(x(i, :) - point, normal)
  h = ri - s
  wall_contact = .false.
  if (.not. (h > 0.0_dp)) return
  wall_contact = .true.
  n = -normal
  di = (ri - h*0.5_dp)*n
  u = v(i, :) - vw
  u = u + cross(w(i, :), di)
  call contact_force(n, h, u, ri, m(i), hertz, gamma_n, gamma_t, mu, f_i, f_t)
  f(i, :) = f(i, :) + f_i
  t(i, :) = t(i, :) + cross(di, f_t)
end function wall_contact
