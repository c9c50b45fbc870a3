//! The time-integration methods, declared once: each row of `method_table!`'s one invocation
//! gives a method's [`Method`] variant (with its payload and documentation), its canonical
//! spelling and aliases ([`SPELLINGS`]) and the backends that implement it, from which the
//! backends' own method enums ([`FemMethod`], [`FdmMethod`], [`ModalMethod`]) and the
//! conversions both ways are generated. A new method is one row here (plus its implementation
//! in its backend).
//!
//! The rows are in the order messages list the spellings ([`Method::names_for`]).

use serde::{Deserialize, Serialize};

/// One backend's method enum — each variant a [`Method`] variant of the same name (with its
/// payload) — with the conversions both ways: `From<Backend> for Method` and the accessor
/// `Method::accessor(self) -> Option<Backend>`.
macro_rules! backend_methods {
    (
        $(#[$doc:meta])*
        $name:ident ($($derive:ident),*), $accessor:ident {
            $($variant:ident $({ $field:ident: $fty:ty })?),* $(,)?
        }
    ) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq $(, $derive)*)]
        pub enum $name {
            $(
                #[doc = concat!("[`Method::", stringify!($variant), "`].")]
                $variant $({ $field: $fty })?
            ),*
        }

        impl From<$name> for Method {
            fn from(m: $name) -> Method {
                match m {
                    $($name::$variant $({ $field })? => Method::$variant $({ $field })?),*
                }
            }
        }

        impl Method {
            #[doc = concat!("This method as [`", stringify!($name), "`], if that backend implements it.")]
            pub fn $accessor(self) -> Option<$name> {
                match self {
                    $(Method::$variant $({ $field })? => Some($name::$variant $({ $field })?),)*
                    _ => None,
                }
            }
        }
    };
}

/// The method table: `Variant [{ field: Type = spelled_default }] => "spelling" [aliases] for
/// backends;` per method. Generates [`Method`], [`SPELLINGS`] and, by sorting the rows into
/// per-backend lists (`@split`), the three backend enums through `backend_methods!`.
macro_rules! method_table {
    ($(
        $(#[$doc:meta])*
        $variant:ident $({ $field:ident: $fty:ty = $spelled:expr })?
            => $name:literal [$($alias:literal),*] for $($backend:ident)+;
    )*) => {
        /// A time-integration method, as `time.method` (case files) and `--method` (CLI) spell
        /// it.
        ///
        /// The spelling-level union of every backend's methods: each backend's typed settings
        /// hold its own subset ([`FemMethod`], [`FdmMethod`], [`ModalMethod`]), and the
        /// conversion to them refuses the others naming that subset. Spellings are parsed
        /// here, once ([`Method::names`]).
        #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
        #[serde(try_from = "String", into = "String")]
        pub enum Method {
            $($(#[$doc])* $variant $({ $field: $fty })?,)*
        }

        /// Every method with its canonical spelling and its aliases (a payload at the value its
        /// bare spelling means), in the order the messages list them. The spellings are read
        /// ([`std::str::FromStr`]) and written ([`Method::name`]) from this table alone.
        pub(crate) const SPELLINGS: &[(Method, &str, &[&str])] = &[
            $((Method::$variant $({ $field: $spelled })?, $name, &[$($alias),*]),)*
        ];

        method_table!(@split [] [] [] $(($variant $({ $field: $fty })?) [$($backend)+])*);
    };
    // All rows sorted: emit the backend enums.
    (@split [$($fem:tt)*] [$($fdm:tt)*] [$($modal:tt)*]) => {
        backend_methods! {
            /// A time-integration method of the FEM backend.
            FemMethod (Eq), fem { $($fem)* }
        }
        backend_methods! {
            /// A time-integration method of the FDM backend (ν of Robert–Asselin None: the
            /// backend's default).
            FdmMethod (), fdm { $($fdm)* }
        }
        backend_methods! {
            /// A time-integration method of the modal backend.
            ModalMethod (Eq), modal { $($modal)* }
        }
    };
    // The next row's next backend.
    (@split [$($fem:tt)*] [$($fdm:tt)*] [$($modal:tt)*] ($($v:tt)*) [fem $($b:ident)*] $($rows:tt)*) => {
        method_table!(@split [$($fem)* $($v)*,] [$($fdm)*] [$($modal)*] ($($v)*) [$($b)*] $($rows)*);
    };
    (@split [$($fem:tt)*] [$($fdm:tt)*] [$($modal:tt)*] ($($v:tt)*) [fdm $($b:ident)*] $($rows:tt)*) => {
        method_table!(@split [$($fem)*] [$($fdm)* $($v)*,] [$($modal)*] ($($v)*) [$($b)*] $($rows)*);
    };
    (@split [$($fem:tt)*] [$($fdm:tt)*] [$($modal:tt)*] ($($v:tt)*) [modal $($b:ident)*] $($rows:tt)*) => {
        method_table!(@split [$($fem)*] [$($fdm)*] [$($modal)* $($v)*,] ($($v)*) [$($b)*] $($rows)*);
    };
    // A row whose backends are all placed.
    (@split [$($fem:tt)*] [$($fdm:tt)*] [$($modal:tt)*] ($($v:tt)*) [] $($rows:tt)*) => {
        method_table!(@split [$($fem)*] [$($fdm)*] [$($modal)*] $($rows)*);
    };
}

method_table! {
    /// fem: energy-consistent implicit midpoint (discrete gradient) for free-joint chains.
    EnergyMidpoint => "energy-midpoint" [] for fem;
    /// fem: implicit generalized-α (Chung–Hulbert).
    GeneralizedAlpha => "generalized-alpha" [] for fem;
    /// fdm: the report's two-step central difference.
    Report => "report" [] for fdm;
    /// Explicit central difference: fem's velocity-Verlet form; fdm's report scheme.
    CentralDifference => "central-difference" [] for fem fdm;
    /// fem: implicit midpoint rule (one-stage Gauss).
    ImplicitMidpoint => "implicit-midpoint" [] for fem;
    /// fem: Bathe's composite method (trapezoidal half step, three-point backward difference).
    Bathe => "bathe" [] for fem;
    /// fdm: the report's scheme with a Robert–Asselin filter of coefficient ν (None: the
    /// backend's default ν). Spelled `robert-asselin` or `robert-asselin=ν`.
    RobertAsselin { nu: Option<f64> = None } => "robert-asselin" [] for fdm;
    /// fdm: one-step velocity (kick–drift–kick) form.
    VelocityForm => "velocity-form" [] for fdm;
    /// modal: adaptive Dormand–Prince 5(4).
    Dopri5 => "dopri5" [] for modal;
    /// modal: adaptive TR-BDF2 (also spelled `tr-bdf2`, `sdirk`).
    TrBdf2 => "trbdf2" ["tr-bdf2", "sdirk"] for modal;
    /// modal: TR-BDF2 at a fixed step.
    TrBdf2Fixed => "trbdf2-fixed" [] for modal;
    /// modal: trapezoidal rule at a fixed step.
    Trapezoid => "trapezoid" [] for modal;
    /// modal: exponential Runge–Kutta (ETDRK4) on the linearized oscillators, fixed step.
    Exponential => "exponential" ["etdrk4"] for modal;
}
